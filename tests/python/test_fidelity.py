"""The fidelity levels (docs/fidelity.md, "Levels"): one config and stats schema for all.

Hit equality of every level on every scene is in test_model.py (CONFIGS "functional",
"analytic", "detailed"); here:

- the analytic model never predicts faster than the physical roofline of its own inputs, on
  several configurations (bounds recomputed here from the counters it reports);
- the detailed level reports DRAM row-buffer outcomes that add up, and models the L2's MSHRs;
- approx models DRAM banks too, or bandwidth calendars with dram.model=bandwidth;
- every level writes the same summary keys (null where a level cannot know).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

import test_model
from test_model import Sim

# The session fixtures of test_model.py (one rtsim-sim and one trace per scene).
sim = test_model.sim
trace_of = test_model.trace_of

LEVELS = ["functional", "analytic", "approx", "detailed"]
ANALYTIC_CONFIGS = {
    "default": [],
    "shared_pipes": ["box.sharing=shared", "triangle.sharing=shared", "box.shared_count=2"],
    "narrow_dram": ["dram.bytes_per_cycle=2", "dram.channels=1"],
    "slow_l2_banks": ["l2.banks=1", "l2.bank_cycles=4"],
    "few_contexts": ["traversal.ray_contexts=2", "traversal.units=4"],
    "slow_scheduler": ["traversal.issue_cycles=32"],
    "ideal_memory": ["ideal_memory=true"],
}


def stats_of(run: Path) -> dict[str, Any]:
    return json.loads((run / "stats.json").read_text())


@pytest.fixture(scope="module")
def hairball(trace_of: Callable[[str, str], Path]) -> Path:
    return trace_of("hairball", "hairball")


def roofline(stats: dict[str, Any], config: dict[str, Any]) -> dict[str, float]:
    """The throughput bounds of a run, recomputed from its own counters and config."""
    m, t = stats["model"], config["traversal"]
    bounds = {}
    for pipe in ("box", "triangle", "anyhit"):
        blocks = m.get(pipe, {}).values()
        issues = sum(b["issues"] for b in blocks)
        pipelines = sum(b["pipelines"] for b in blocks)
        if pipelines:
            bounds[pipe] = issues * config[pipe]["initiation_interval"] / pipelines
    steps = sum(u["steps"] for u in m["units"].values())
    bounds["scheduler"] = steps * t["issue_cycles"] / t["units"]
    if "dram" in m:
        d, dc = m["dram"], config["dram"]
        bounds["dram"] = (d["read_bytes"] + d["write_bytes"]) / (
            dc["channels"] * dc["bytes_per_cycle"]
        )
        l2 = m["l2"]
        bounds["l2_banks"] = (
            (l2["reads"] + l2["writes"]) * config["l2"]["bank_cycles"] / config["l2"]["banks"]
        )
    return bounds


@pytest.mark.parametrize("config", list(ANALYTIC_CONFIGS))
def test_analytic_never_faster_than_its_roofline(
    hairball: Path,
    sim: Sim,
    tmp_path: Path,
    config: str,
) -> None:
    result = sim(hairball, tmp_path / "run", "fidelity=analytic", *ANALYTIC_CONFIGS[config])
    assert result.returncode == 0, result.stderr
    stats = stats_of(tmp_path / "run")
    resolved = json.loads((tmp_path / "run" / "config.resolved.json").read_text())
    cycles = stats["summary"]["cycles"]
    analytic = stats["model"]["analytic"]
    assert cycles == analytic["cycles"] > 0
    # Every bound the model reports, and the same bounds recomputed from its counters.
    for name, bound in analytic["bounds"].items():
        assert cycles >= bound - 1e-6, f"{name}: {cycles} < {bound}"
    recomputed = roofline(stats, resolved)
    for name, bound in recomputed.items():
        assert analytic["bounds"][name] == pytest.approx(bound, rel=1e-9), name
        assert cycles >= bound - 1e-6, f"{name}: {cycles} < {bound}"
    assert analytic["binding"] in analytic["bounds"]
    assert cycles >= analytic["roofline_cycles"] - 1e-6
    assert cycles >= analytic["queueing_cycles"] - 1e-6
    # The configured limit shows up where it should.
    expected = {"narrow_dram": "dram", "slow_l2_banks": "l2_banks", "slow_scheduler": "scheduler"}
    if config in expected:
        assert analytic["binding"] == expected[config]


def test_detailed_reports_row_buffer_outcomes(hairball: Path, sim: Sim, tmp_path: Path) -> None:
    runs = {}
    for policy in ("open", "close"):
        out = tmp_path / policy
        result = sim(hairball, out, "fidelity=detailed", f"dram.page_policy={policy}")
        assert result.returncode == 0, result.stderr
        runs[policy] = stats_of(out)
    for policy, stats in runs.items():
        d = stats["model"]["dram"]
        outcomes = d["row_hits"] + d["row_misses"] + d["row_conflicts"]
        assert outcomes == d["reads"] + d["writes"] > 0
        assert sum(b["accesses"] for b in d["by_bank"]) == outcomes
        assert d["page_policy"] == policy
        assert stats["model"]["l2"]["config"]["mshrs"] == 64  # modelled at detailed
    # Close page never finds a row open.
    assert runs["close"]["model"]["dram"]["row_hits"] == 0
    assert runs["close"]["model"]["dram"]["row_conflicts"] == 0
    assert runs["open"]["model"]["dram"]["row_hits"] > 0


def test_approx_models_dram_banks_unless_told_bandwidth(
    hairball: Path, sim: Sim, tmp_path: Path
) -> None:
    """dram.model: banks and row buffers at approx by default; bandwidth calendars on request."""
    runs = {}
    for model in ("banks", "bandwidth"):
        out = tmp_path / model
        result = sim(hairball, out, "fidelity=approx", f"dram.model={model}")
        assert result.returncode == 0, result.stderr
        runs[model] = stats_of(out)
    banks, bandwidth = runs["banks"]["model"]["dram"], runs["bandwidth"]["model"]["dram"]
    assert (
        banks["row_hits"] + banks["row_misses"] + banks["row_conflicts"]
        == banks["reads"] + banks["writes"]
    )
    assert "row_hits" not in bandwidth
    # About the same traffic (timing moves merges and evictions a little), different timing.
    assert banks["read_bytes"] == pytest.approx(bandwidth["read_bytes"], rel=0.01)
    assert runs["banks"]["summary"]["cycles"] != runs["bandwidth"]["summary"]["cycles"]


def test_bank_timing_longer_than_the_latency_is_refused(
    hairball: Path, sim: Sim, tmp_path: Path
) -> None:
    result = sim(hairball, tmp_path / "bad", "fidelity=approx", "dram.latency=20")
    assert result.returncode != 0
    assert "dram.latency" in result.stderr and "dram.model=bandwidth" in result.stderr
    ok = sim(
        hairball, tmp_path / "ok", "fidelity=approx", "dram.latency=20", "dram.model=bandwidth"
    )
    assert ok.returncode == 0, ok.stderr
    # The analytic level runs no bank model: nothing to refuse.
    analytic = sim(hairball, tmp_path / "analytic", "fidelity=analytic", "dram.latency=20")
    assert analytic.returncode == 0, analytic.stderr


def test_ddr4_limits_slow_the_banks_and_count_their_waits(
    hairball: Path, sim: Sim, tmp_path: Path
) -> None:
    from rtsim.config import MODIFIERS

    ddr4 = [f"dram.{k}={v}" for k, v in MODIFIERS["ddr4"]["dram"].items()]
    runs = {}
    for name, sets in (("first", []), ("ddr4", ddr4)):
        result = sim(hairball, tmp_path / name, "fidelity=detailed", "dram.channels=1", *sets)
        assert result.returncode == 0, result.stderr
        runs[name] = stats_of(tmp_path / name)
    first, ddr4_run = runs["first"]["model"]["dram"], runs["ddr4"]["model"]["dram"]
    assert first["ras_wait_cycles"] == first["activate_wait_cycles"] == 0
    assert (
        first["refresh_wait_cycles"]
        == first["column_wait_cycles"]
        == first["queue_wait_cycles"]
        == 0
    )
    assert ddr4_run["ras_wait_cycles"] > 0 and ddr4_run["activate_wait_cycles"] > 0
    assert ddr4_run["column_wait_cycles"] > 0 and ddr4_run["bank_groups"] == 4
    assert runs["ddr4"]["summary"]["cycles"] > runs["first"]["summary"]["cycles"]
    assert runs["ddr4"]["validation"]["hit_mismatches"] == 0
    # A refresh longer than its interval is refused, naming both fields.
    bad = sim(hairball, tmp_path / "bad", "dram.t_refi=100", "dram.t_rfc=200")
    assert bad.returncode == 2
    # Bank groups that do not divide the banks are refused, naming both fields.
    uneven = sim(hairball, tmp_path / "uneven", "dram.bank_groups=3")
    assert uneven.returncode == 2 and "dram.bank_groups" in uneven.stderr
    assert "dram.banks" in uneven.stderr
    assert "dram.t_rfc" in bad.stderr and "dram.t_refi" in bad.stderr, bad.stderr


def test_every_level_writes_the_same_summary_keys(hairball: Path, sim: Sim, tmp_path: Path) -> None:
    keys = {}
    for level in LEVELS:
        result = sim(hairball, tmp_path / level, f"fidelity={level}")
        assert result.returncode == 0, result.stderr
        stats = stats_of(tmp_path / level)
        assert stats["fidelity"] == stats["summary"]["fidelity"] == level
        keys[level] = set(stats["summary"])
        if level == "functional":
            assert stats["summary"]["cycles"] is None
            assert stats["summary"]["dram_bytes"] is None
        else:
            assert stats["summary"]["cycles"] > 0
            assert stats["summary"]["dram_bytes"] > 0
    # Same keys everywhere (sampling may add its own to all levels alike).
    assert all(k == keys["approx"] for k in keys.values()), {
        k: v ^ keys["approx"] for k, v in keys.items()
    }


def test_detailed_synchronises_only_steps_that_reach_shared_blocks(
    hairball: Path, sim: Sim, tmp_path: Path
) -> None:
    """Detailed with private pipelines: operations phases run without waiting for SystemC time
    (docs/model.md); with shared pipelines every step synchronises. Hits are checked either way."""
    syncs = {}
    for name, settings in {
        "private": [],
        "shared": ["box.sharing=shared", "triangle.sharing=shared"],
    }.items():
        out = tmp_path / name
        result = sim(hairball, out, "fidelity=detailed", *settings)
        assert result.returncode == 0, result.stderr
        stats = stats_of(out)
        assert stats["summary"]["hit_mismatches"] == 0 and stats["summary"]["work_mismatches"] == 0
        units = stats["model"]["units"].values()
        syncs[name] = sum(u["quantum_syncs"] for u in units) / sum(u["steps"] for u in units)
    assert syncs["private"] < 0.75 * syncs["shared"]
