"""The analytic level's per-trace analysis (docs/fidelity.md, "The analytic level"):

- a second configuration reuses the analysis beside the trace; a different unit count, or a
  changed trace in the same folder, does not;
- every ray the analysis steps is checked (zero mismatches) and stats.json says what was checked;
- its statistical hit rates stay close to the functional caches' (analytic.caches=functional,
  the exact model, which checks every ray) on a trace both can run.
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

import test_model
from test_model import Sim

sim = test_model.sim
trace_of = test_model.trace_of


def run(sim: Sim, trace: Path, out: Path, *sets: str) -> dict[str, Any]:
    result = sim(trace, out, "fidelity=analytic", *sets, extra=("--no-verdict",))
    assert result.returncode == 0, result.stderr
    return json.loads((out / "stats.json").read_text())


def analysis(stats: dict[str, Any]) -> dict[str, Any]:
    return stats["model"]["analytic"]["analysis"]


@pytest.fixture()
def own_trace(trace_of: Callable[[str, str], Path], tmp_path: Path) -> Path:
    """A private copy of the hairball trace (its analyses are written beside it)."""
    out = tmp_path / "trace"
    shutil.copytree(
        trace_of("hairball", "hairball"), out, ignore=shutil.ignore_patterns("analytic")
    )
    return out


def test_second_configuration_reuses_the_analysis(
    own_trace: Path, sim: Sim, tmp_path: Path
) -> None:
    first = run(sim, own_trace, tmp_path / "a")
    assert analysis(first)["reused"] is False
    assert Path(analysis(first)["file"]).parent == own_trace / "analytic"
    # Cache sizes, DRAM and pipelines are evaluated per run: the same analysis.
    second = run(sim, own_trace, tmp_path / "b", "l1.size_kib=64", "dram.bytes_per_cycle=4")
    assert analysis(second)["reused"] is True
    assert analysis(second)["file"] == analysis(first)["file"]
    assert second["summary"]["cycles"] != first["summary"]["cycles"]
    assert second["summary"]["l1_hit_rate"] > first["summary"]["l1_hit_rate"]
    # Units shape the access streams: a new analysis, in its own file.
    third = run(sim, own_trace, tmp_path / "c", "traversal.units=4")
    assert analysis(third)["reused"] is False
    assert analysis(third)["file"] != analysis(first)["file"]
    # Reused answers are the same answers.
    again = run(sim, own_trace, tmp_path / "d")
    assert analysis(again)["reused"] is True
    assert again["summary"]["cycles"] == first["summary"]["cycles"]


def test_a_changed_trace_is_analysed_anew(
    own_trace: Path, trace_of: Callable[[str, str], Path], sim: Sim, tmp_path: Path
) -> None:
    first = run(sim, own_trace, tmp_path / "a")
    # Another trace's content in the same folder (same file name): the key's identity differs.
    shutil.copy(trace_of("cornell", "cornell") / "trace.rtt", own_trace / "trace.rtt")
    shutil.copy(trace_of("cornell", "cornell") / "manifest.json", own_trace / "manifest.json")
    second = run(sim, own_trace, tmp_path / "b")
    assert analysis(second)["reused"] is False
    assert analysis(second)["key"]["trace"] != analysis(first)["key"]["trace"]
    assert second["summary"]["rays"] != first["summary"]["rays"] or (
        second["summary"]["cycles"] != first["summary"]["cycles"]
    )


def test_sampled_rays_are_checked_and_the_scope_is_stated(
    own_trace: Path, sim: Sim, tmp_path: Path
) -> None:
    # A sample smaller than the trace: 2 clusters of 64 + 64 rays (plus each cluster's tail).
    sets = [
        "analytic.whole_trace_rays=100", "analytic.clusters=2", "analytic.warmup_rays=64",
        "analytic.measured_rays=64", "traversal.units=2", "traversal.ray_contexts=4",
    ]  # fmt: skip
    stats = run(sim, own_trace, tmp_path / "a", *sets)
    v = stats["validation"]
    assert (
        v["rays_checked"]
        == v["rays_expected"]
        == analysis(stats)["stepped_rays"]
        == 2 * (64 + 64 + 8)
    )
    assert v["rays_checked"] < stats["summary"]["rays"]
    assert stats["summary"]["hit_mismatches"] == stats["summary"]["work_mismatches"] == 0
    assert "sampled rays are checked" in v["scope"]
    assert analysis(stats)["sample_rays"] == 2 * 64


def test_statistical_hit_rates_track_the_functional_caches(
    own_trace: Path, sim: Sim, tmp_path: Path
) -> None:
    for i, sets in enumerate(
        [[], ["l1.size_kib=4", "l2.size_kib=64"], ["l1.ways=1", "l2.size_kib=256"]]
    ):
        stat = run(sim, own_trace, tmp_path / f"s{i}", *sets)
        exact = run(sim, own_trace, tmp_path / f"f{i}", "analytic.caches=functional", *sets)
        assert exact["validation"]["rays_checked"] == exact["summary"]["rays"]  # every ray
        assert exact["model"]["analytic"]["caches"] == "functional"
        s, f = stat["summary"], exact["summary"]
        assert s["l1_hit_rate"] == pytest.approx(f["l1_hit_rate"], abs=0.05), sets
        assert s["l2_hit_rate"] == pytest.approx(f["l2_hit_rate"], abs=0.10), sets
        assert s["cycles"] == pytest.approx(f["cycles"], rel=0.15), sets
