"""DRAM bandwidth over time never shows a bucket above the peak: bytes are counted when they
move on the channel at its rate (with the bank model, on the data bus after the column command),
split between buckets when a transfer straddles one's end. Counted when the bank started, a
narrow channel showed 1.10x its peak."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from test_model import Sim, hairball, sim, trace_of  # noqa: F401  (fixtures)


@pytest.mark.parametrize("model", ["banks", "bandwidth"])
def test_bandwidth_over_time_stays_under_the_peak(
    hairball: Path, sim: Sim, tmp_path: Path, model: str  # noqa: F811
) -> None:  # fmt: skip
    out = tmp_path / model
    sets = ("dram.bytes_per_cycle=1", "dram.channels=1", f"dram.model={model}")
    result = sim(hairball, out, *sets)
    assert result.returncode == 0, result.stderr
    dram = json.loads((out / "stats.json").read_text())["model"]["dram"]
    peak = dram["peak_bandwidth_gbps"]
    series = [p["gbps"] for p in dram["bandwidth_over_time"]]
    assert max(series) <= peak * 1.001, max(series) / peak
    assert max(series) >= peak * 0.9  # one byte a cycle: the channel is saturated
