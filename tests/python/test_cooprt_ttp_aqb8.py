"""Cooperative lanes (CoopRT, traversal.simt.cooperative), stack-driven prefetching (TTP,
traversal.stack_prefetch) and AQB8-style quantised box tests (traversal.quantized_boxes): every
hit and every ray's work identical to the reference at every level each runs at; helpers raise
SIMD efficiency and shorten warp-refill runs; the stack prefetcher's lines are nearly all read;
the quantised pipeline walks a little more on a much smaller box pipeline; each is priced in
area and energy; a structure or unit that cannot take one says so."""

from __future__ import annotations

from pathlib import Path

import pytest

import rtsim
from conftest import checked, sim_stats, simulate

WARPS = (
    "traversal.model=simt",
    "traversal.units=2",
    "traversal.ray_contexts=64",
    "traversal.simt.lanes=32",
    "traversal.simt.refill=warp",
)
COOP = "traversal.simt.cooperative=true"
TTP = "traversal.stack_prefetch=2"


def _units(stats: dict) -> list[dict]:
    return list(stats["model"]["units"].values())


def _l1_prefetch(stats: dict) -> dict[str, int]:
    total: dict[str, int] = {}
    for cache in stats["model"]["l1"].values():
        for k, v in cache.get("prefetch", {}).items():
            total[k] = total.get(k, 0) + v
    return total


@pytest.mark.parametrize("level", ["approx", "detailed"])
def test_cooperative_lanes_keep_hits_and_work_and_help(
    sim_exe: Path, small_hairball_traces: dict[str, Path], tmp_path: Path, level: str
) -> None:
    for accel in ("bvh2", "cwbvh8"):
        trace = small_hairball_traces[accel] / "trace.rtt"
        at = f"fidelity={level}"
        base = checked(sim_exe, trace, tmp_path / f"{accel}_base", *WARPS, at)
        coop = checked(sim_exe, trace, tmp_path / f"{accel}_coop", *WARPS, COOP, at)
        steps = sum(u["helper_steps"] for u in _units(coop))
        assert steps > 0 and all(u["helper_steps"] == 0 for u in _units(base))
        helped = sum(u["helped_warp_steps"] for u in _units(coop))
        assert helped <= sum(u["warp_steps"] for u in _units(coop))
        # Helpers are active lanes: the warps run fewer steps, more of their lanes busy.
        assert coop["summary"]["simd_efficiency"] > base["summary"]["simd_efficiency"]
        assert coop["summary"]["cycles"] < base["summary"]["cycles"]
        acc = coop["model"]["cycle_accounting"]
        assert sum(acc["by_use"].values()) == acc["context_cycles"]
        assert coop["area"]["mm2"]["cooperation"] > 0 and "cooperation" not in base["area"]["mm2"]
        assert coop["energy"]["per_ray_nj"]["cooperation"] > 0


def test_cooperative_lanes_with_treelet_queues_and_at_the_analytic_level(
    sim_exe: Path, small_hairball_traces: dict[str, Path], tmp_path: Path
) -> None:
    trace = small_hairball_traces["bvh2"] / "trace.rtt"
    queued = checked(sim_exe, trace, tmp_path / "treelets", *WARPS, COOP, "treelets.enabled=true")
    assert sum(u["rays_parked"] for u in _units(queued)) > 0
    assert sum(u["helper_steps"] for u in _units(queued)) > 0
    # The analytic level prices cooperation from the functional warp profile, which lends idle
    # lanes as the unit does: fewer warp steps, more active lanes.
    base = sim_stats(sim_exe, trace, tmp_path / "analytic_base", *WARPS, "fidelity=analytic")
    coop = sim_stats(sim_exe, trace, tmp_path / "analytic_coop", *WARPS, COOP, "fidelity=analytic")
    assert coop["summary"]["cycles"] < base["summary"]["cycles"]


@pytest.mark.parametrize(
    "unit",
    [("traversal.model=mimd",), WARPS, ("traversal.model=packet", "traversal.packet.lanes=16")],
    ids=["mimd", "simt", "packet"],
)
def test_stack_prefetch_keeps_hits_and_work_and_is_read(
    sim_exe: Path, small_hairball_traces: dict[str, Path], tmp_path: Path, unit: tuple[str, ...]
) -> None:
    for accel in ("bvh2", "cwbvh8"):
        trace = small_hairball_traces[accel] / "trace.rtt"
        base = checked(sim_exe, trace, tmp_path / f"{accel}_base", *unit)
        ttp = checked(sim_exe, trace, tmp_path / f"{accel}_ttp", *unit, TTP)
        sp = [u["stack_prefetch"] for u in _units(ttp)]
        assert sum(p["triggers"] for p in sp) > 0 and sum(p["sent"] for p in sp) > 0
        assert all("stack_prefetch" not in u for u in _units(base))
        pf = _l1_prefetch(ttp)
        # No address is predicted: a line requested for a stack entry is read unless the pop
        # skips the entry (entered beyond the best hit) or the line is evicted first.
        assert pf["useful"] >= 0.7 * pf["issued"], pf
        assert _l1_prefetch(base) == {} or _l1_prefetch(base).get("issued", 0) == 0
        assert ttp["area"]["mm2"]["stack_prefetcher"] > 0
        assert "stack_prefetcher" in ttp["energy"]["per_ray_nj"]


def test_stack_prefetch_with_cooperative_lanes_prefetches_from_the_recorded_walks(
    sim_exe: Path, small_hairball_traces: dict[str, Path], tmp_path: Path
) -> None:
    trace = small_hairball_traces["cwbvh8"] / "trace.rtt"
    both = checked(sim_exe, trace, tmp_path / "both", *WARPS, COOP, TTP)
    sp = [u["stack_prefetch"] for u in _units(both)]
    assert sum(p["triggers"] for p in sp) > 0 and sum(p["sent"] for p in sp) > 0
    assert sum(u["helper_steps"] for u in _units(both)) > 0


def test_stack_prefetch_unused_where_no_stack_holds_addresses(
    sim_exe: Path, small_hairball_traces: dict[str, Path], tmp_path: Path
) -> None:
    def unused(trace: Path, name: str, *sets: str) -> dict[str, str]:
        stats = checked(sim_exe, trace, tmp_path / name, TTP, *sets)
        return {u["key"]: u["why"] for u in stats["summary"]["resolved"]["unused"]}

    kd = unused(small_hairball_traces["kdtree"] / "trace.rtt", "kd")
    assert "no stack addresses" in kd["traversal.stack_prefetch"]
    bvh2 = small_hairball_traces["bvh2"] / "trace.rtt"
    assert "traversal.stack_prefetch" in unused(bvh2, "ideal", "ideal_memory=true")
    functional = unused(bvh2, "functional", "fidelity=functional")
    assert "untimed" in functional["traversal.stack_prefetch"]
    # A packet prefetches from its shared stack.
    assert "traversal.stack_prefetch" not in unused(bvh2, "packet", "traversal.model=packet")
    assert "traversal.stack_prefetch" not in unused(bvh2, "used")


@pytest.mark.parametrize("unit", [("traversal.model=mimd",), WARPS], ids=["mimd", "simt"])
def test_quantized_boxes_keep_hits_and_work_on_a_narrow_pipeline(
    sim_exe: Path, small_hairball_traces: dict[str, Path], tmp_path: Path, unit: tuple[str, ...]
) -> None:
    trace = small_hairball_traces["cwbvh8"] / "trace.rtt"
    for level in ("approx", "detailed", "analytic"):
        base = checked(sim_exe, trace, tmp_path / f"{level}_fp", *unit, f"fidelity={level}")
        q = checked(
            sim_exe, trace, tmp_path / f"{level}_q", *unit, f"fidelity={level}",
            "traversal.quantized_boxes=true",
        )  # fmt: skip
        bp = q["box_precision"]
        assert bp["arithmetic"] == "quantized_int" and bp["bits"] == 8
        # One grid cell of slack enters a few boxes the fp32 test rejects (mostly leaves).
        assert bp["box_hits"] > 0 and bp["extra_steps_fraction"] < 0.5, (level, bp)
        assert bp["box_test_pj"] < 0.3 * bp["box_test_pj_fp32"]
        # The integer pipeline replaces the dequantiser with a requantiser and narrows the box
        # pipeline's arithmetic.
        area = q["area"]["mm2"]
        assert "node_decoder" not in area and area["ray_requantizer"] > 0
        assert area["box"] < 0.3 * base["area"]["mm2"]["box"]
        assert "box_precision" not in base


def test_quantized_boxes_refused_where_nodes_hold_fp32_boxes(
    sim_exe: Path, small_hairball_traces: dict[str, Path], tmp_path: Path
) -> None:
    r = simulate(
        sim_exe, small_hairball_traces["bvh2"] / "trace.rtt", tmp_path / "bvh2",
        "traversal.quantized_boxes=true",
    )  # fmt: skip
    assert r.returncode == 2 and "quantised nodes" in r.stderr and "cwbvh" in r.stderr
    r = simulate(
        sim_exe, small_hairball_traces["cwbvh8"] / "trace.rtt", tmp_path / "both",
        "traversal.quantized_boxes=true", "traversal.box_precision_bits=7",
    )  # fmt: skip
    assert r.returncode == 2 and "box_precision_bits=0" in r.stderr


def test_two_level_blases_take_stack_prefetch_and_quantized_boxes(
    sim_exe: Path, tmp_path: Path
) -> None:
    from conftest import rtsim_trace

    trace = tmp_path / "grove"
    rtsim_trace(
        "grove", "-o", str(trace), "--accel", "cwbvh8", "--resolution", "16x12",
        "--workload", "primary,diffuse",
    )  # fmt: skip
    assert rtsim.open_trace(trace).manifest["accel"]["kind"] == "two_level"
    for unit in (("traversal.model=mimd",), WARPS):
        stats = checked(
            sim_exe, trace / "trace.rtt", tmp_path / unit[0].split("=")[1], *unit, TTP,
            "traversal.quantized_boxes=true",
        )  # fmt: skip
        assert stats["summary"]["resolved"]["unused"] == []
        assert sum(u["stack_prefetch"]["triggers"] for u in _units(stats)) > 0
        assert stats["box_precision"]["arithmetic"] == "quantized_int"
