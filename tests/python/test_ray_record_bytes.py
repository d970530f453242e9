"""Ray records in DRAM (docs/stats.md, "How to read a run"): a 40-byte record packed at a 40-byte
stride spans 1.5 lines of 64 bytes on average, so a run reads between 40 bytes per ray (every
line kept until its neighbouring records are read) and 96 (none kept); caches too small to keep
the ray lines read more than 40, caches that keep them read exactly 40."""

from __future__ import annotations

from pathlib import Path

import pytest

from conftest import sim_stats


def ray_bytes_per_ray(stats: dict) -> float:
    return stats["model"]["dram"]["by_kind"]["ray"]["read_bytes"] / stats["summary"]["rays"]


def test_ray_records_cost_40_to_96_bytes_per_ray(
    cornell_trace: Path, sim_exe: Path, tmp_path: Path
) -> None:
    kept = ray_bytes_per_ray(
        sim_stats(sim_exe, cornell_trace, tmp_path / "kept", "l2.size_kib=16384")
    )
    assert kept == pytest.approx(40.0, abs=0.1)  # the last line is read whole
    # Tiny caches evict a ray line before its neighbouring records are read.
    starved = ray_bytes_per_ray(
        sim_stats(sim_exe, cornell_trace, tmp_path / "starved", "l1.size_kib=1", "l1.ways=2",
                  "l2.size_kib=1", "l2.ways=2", "traversal.units=4")
    )  # fmt: skip
    assert 41.0 < starved <= 96.0
