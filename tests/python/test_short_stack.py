"""Short stacks with a restart trail end to end (docs/accel.md, "Short stacks"): on a binary and a
compressed wide BVH, at every level that takes them, a short stack changes no hit and no reference
work count (the hit checker compares them with the trace), restarts and revisits are reported in
the `short_stack` section, no stack entry is spilled, and the restarts cost node steps the units
see; a stack as deep as the structure can need never restarts and times exactly like the
spilling stack of that size; the knob is a config field with its range and choices, refused by
name where it cannot run."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

import rtsim
from conftest import checked, simulate
from rtsim.sweep.spec import SpecError, parse_spec

SHORT = "traversal.stack_overflow=restart_trail"


def spilled(stats: dict[str, Any]) -> int:
    return sum(
        u["stack_spill_writes"] + u["stack_spill_reads"] for u in stats["model"]["units"].values()
    )


@pytest.mark.parametrize("level", ["functional", "approx", "detailed"])
@pytest.mark.parametrize("accel", ["bvh2", "cwbvh8"])
def test_short_stack_keeps_hits_and_reference_work(
    small_hairball_traces: dict[str, Path], sim_exe: Path, tmp_path: Path, accel: str, level: str
) -> None:
    stats = checked(
        sim_exe,
        small_hairball_traces[accel],
        tmp_path / "s",
        SHORT,
        "traversal.stack_entries=1",
        f"fidelity={level}",
    )
    ss = stats["short_stack"]
    assert ss["entries"] == 1 and ss["policy"] == "restart_trail"
    assert ss["restarts"] > 0 and ss["restart_steps"] >= ss["restarts"] and ss["stack_drops"] > 0
    assert 0 < ss["extra_steps_fraction"] < 5
    if level != "functional":
        assert spilled(stats) == 0
        # The units scheduled the revisits: two slots per step beyond the full stack's.
        full = checked(sim_exe, small_hairball_traces[accel], tmp_path / "f",
                       "traversal.stack_entries=64", f"fidelity={level}")  # fmt: skip
        steps = sum(u["steps"] for u in stats["model"]["units"].values())
        full_steps = sum(u["steps"] for u in full["model"]["units"].values())
        assert steps == full_steps + 2 * ss["restart_steps"]
        assert "short_stack" not in full


def test_a_deep_enough_short_stack_never_restarts(
    small_hairball_traces: dict[str, Path], sim_exe: Path, tmp_path: Path
) -> None:
    short = checked(
        sim_exe, small_hairball_traces["bvh2"], tmp_path / "s", SHORT, "traversal.stack_entries=64"
    )
    spill = checked(
        sim_exe, small_hairball_traces["bvh2"], tmp_path / "p", "traversal.stack_entries=64"
    )
    ss = short["short_stack"]
    assert ss["restarts"] == ss["restart_steps"] == ss["stack_drops"] == 0
    assert short["summary"]["cycles"] == spill["summary"]["cycles"]
    assert short["summary"]["dram_bytes_per_ray"] == spill["summary"]["dram_bytes_per_ray"]


def test_short_stack_is_refused_by_name_where_it_cannot_run(
    small_hairball_traces: dict[str, Path], sim_exe: Path, tmp_path: Path
) -> None:
    # kd-trees restart by kd-restart with push-down; the statistical analytic level scales the
    # restarts it measures on its stepped sample
    stats = checked(
        sim_exe, small_hairball_traces["kdtree"], tmp_path / "k", SHORT, "traversal.stack_entries=2"
    )
    assert stats["short_stack"]["restarts"] > 0
    checked(sim_exe, small_hairball_traces["bvh2"], tmp_path / "a", SHORT, "fidelity=analytic")
    r = simulate(
        sim_exe, small_hairball_traces["bvh2"], tmp_path / "c", "traversal.stack_overflow=pop"
    )
    assert r.returncode == 2 and "traversal.stack_overflow" in r.stderr
    # a packet's rays share one stack; the restart trail is a single ray's
    r = simulate(
        sim_exe, small_hairball_traces["bvh2"], tmp_path / "p", SHORT, "traversal.model=packet"
    )
    assert r.returncode == 2 and "traversal.stack_overflow" in r.stderr and "packet" in r.stderr
    # analytic with functional caches steps every ray and takes it
    stats = checked(
        sim_exe, small_hairball_traces["bvh2"], tmp_path / "af", SHORT, "fidelity=analytic",
        "analytic.caches=functional", "traversal.stack_entries=2",
    )  # fmt: skip
    assert stats["short_stack"]["restarts"] > 0


def test_the_knob_is_a_config_field_and_a_sweep_axis() -> None:
    info = rtsim.config.field_info("traversal.stack_overflow")
    assert info.metadata["choices"] == ("spill", "restart_trail")
    assert rtsim.config.SimConfig().traversal.stack_overflow == "spill"
    spec = parse_spec(
        "scenes: [cornell]\nworkloads: [{rays: [primary]}]\naccel: [cwbvh8]\ngrid:\n"
        "  traversal.stack_overflow: [spill, restart_trail]\n  traversal.stack_entries: [2, 5]\n",
        "s.yaml",
    )
    points = {
        (r.config.traversal.stack_overflow, r.config.traversal.stack_entries) for r in spec.runs()
    }
    assert points == {("spill", 2), ("spill", 5), ("restart_trail", 2), ("restart_trail", 5)}
    with pytest.raises(SpecError, match=r"traversal\.stack_overflow"):
        parse_spec(
            "scenes: [cornell]\nworkloads: [{rays: [primary]}]\ngrid:\n"
            "  traversal.stack_overflow: [restart]\n",
            "s.yaml",
        )
