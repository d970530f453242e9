"""SIMT warps and ray sorting (traversal.model=simt, dispatch.sort): every hit and every ray's
work identical to the reference under each model, policy and sort; SIMD efficiency exactly 1 when
every lane carries the same ray; lanes' cycles accounted; bad settings named."""

from __future__ import annotations

from pathlib import Path

import pytest

import rtsim
from conftest import REPO, sim_stats, simulate

SIMT = ("traversal.model=simt", "traversal.ray_contexts=32")


@pytest.mark.parametrize(
    "sets",
    [
        ("traversal.simt.lanes=8",),
        ("traversal.simt.lanes=16", "traversal.simt.policy=if_if"),
        ("traversal.simt.lanes=32", "traversal.simt.refill=warp"),
        ("traversal.simt.lanes=8", "dispatch.sort=origin_direction", "fidelity=detailed"),
    ],
)
def test_simt_hits_and_work_match_the_reference(
    sim_exe: Path, small_cornell_rays: Path, tmp_path: Path, sets: tuple[str, ...]
) -> None:
    stats = sim_stats(sim_exe, small_cornell_rays / "trace.rtt", tmp_path / "run", *SIMT, *sets)
    s = stats["summary"]
    assert s["hit_mismatches"] == 0 and s["work_mismatches"] == 0
    assert s["rays"] == rtsim.open_trace(small_cornell_rays).manifest["counts"]["rays"]
    units = stats["model"]["units"].values()
    assert sum(u["rays"] for u in units) == s["rays"]
    assert 0.0 < s["simd_efficiency"] < 1.0  # diffuse rays diverge
    lanes = int(next(x for x in sets if x.startswith("traversal.simt.lanes=")).split("=")[1])
    for u in units:
        assert u["lane_slots"] == u["warp_steps"] * lanes
        assert sum(u["active_lane_histogram"]) == u["warp_steps"]
        assert sum(k * n for k, n in enumerate(u["active_lane_histogram"])) == u["active_lanes"]
        assert u["coalesced_requests"] <= 1.1 * u["lane_requests"]  # a read may span 2 lines
        assert set(u["simd_efficiency_by_kind"]) == {"primary", "shadow", "diffuse"}
        assert all(0.0 < v <= 1.0 for v in u["simd_efficiency_by_kind"].values())
        assert all(0.0 <= p["value"] <= 1.0 for p in u["simd_efficiency_over_time"])
    # Every lane-cycle is in one use, idle lanes included.
    acc = stats["model"]["cycle_accounting"]
    assert acc["context_cycles"] == 8 * 32 * s["cycles"]
    assert sum(acc["by_use"].values()) == acc["context_cycles"]
    assert acc["by_use"]["idle_lane"] > 0


def test_simd_efficiency_is_one_when_every_lane_carries_the_same_ray_trace(
    sim_exe: Path, same_ray_trace: Path, tmp_path: Path
) -> None:
    for refill in ("lane", "warp"):
        for policy in ("while_while", "if_if"):
            stats = sim_stats(
                sim_exe,
                same_ray_trace / "trace.rtt",
                tmp_path / f"{refill}_{policy}",
                "traversal.model=simt",
                "traversal.units=1",
                "traversal.ray_contexts=16",
                "traversal.simt.lanes=8",
                f"traversal.simt.refill={refill}",
                f"traversal.simt.policy={policy}",
            )
            assert stats["summary"]["hit_mismatches"] == 0
            assert stats["summary"]["simd_efficiency"] == 1.0
            unit = stats["model"]["units"]["tu0"]
            assert unit["active_lane_histogram"][:8] == [0] * 8
            # One line per warp step for the node fetches: every lane reads the same node.
            assert unit["coalesced_requests"] < unit["lane_requests"] / 4
            assert "idle_lane" not in stats["model"]["cycle_accounting"]["by_use"]
            assert unit["simd_efficiency_by_kind"] == {"primary": 1.0}
            assert {p["value"] for p in unit["simd_efficiency_over_time"]} == {1.0}


def test_mimd_writes_no_simt_keys(sim_exe: Path, small_cornell_rays: Path, tmp_path: Path) -> None:
    stats = sim_stats(sim_exe, small_cornell_rays / "trace.rtt", tmp_path / "run")
    assert "simd_efficiency" not in stats["summary"]
    assert "warp_steps" not in stats["model"]["units"]["tu0"]
    assert "idle_lane" not in stats["model"]["cycle_accounting"]["by_use"]
    assert "sort" not in stats["model"]["dispatch"]


@pytest.mark.parametrize("sort", ["octant", "morton", "origin_direction"])
def test_sorted_dispatch_hands_out_every_ray_once(
    sim_exe: Path, small_cornell_rays: Path, tmp_path: Path, sort: str
) -> None:
    stats = sim_stats(
        sim_exe, small_cornell_rays / "trace.rtt", tmp_path / "run", f"dispatch.sort={sort}"
    )
    s = stats["summary"]
    assert s["hit_mismatches"] == 0 and s["work_mismatches"] == 0
    d = stats["model"]["dispatch"]
    assert d["rays"] == d["sorted_rays"] == s["rays"]
    assert d["sort"] == sort
    assert s["cycles"] >= d["sort_ready_cycle"]  # no ray starts before its window is sorted


@pytest.mark.parametrize(
    ("sets", "named"),
    [
        (("traversal.simt.lanes=3",), "traversal.simt.lanes"),
        (("traversal.simt.lanes=65",), "traversal.simt.lanes"),
        (
            ("traversal.model=simt", "traversal.simt.lanes=12", "traversal.ray_contexts=16"),
            "traversal.ray_contexts",
        ),
        (("traversal.model=simd",), "traversal.model"),
        (
            ("traversal.model=packet", "traversal.packet.lanes=12", "traversal.ray_contexts=16"),
            "traversal.ray_contexts",
        ),
        (("traversal.model=packet", "treelets.enabled=true"), "treelets.enabled"),
        (
            ("traversal.model=simt", "fidelity=analytic", "analytic.caches=functional"),
            "traversal.model",
        ),
        (("traversal.simt.policy=while",), "traversal.simt.policy"),
        (("dispatch.sort=hilbert",), "dispatch.sort"),
        (("dispatch.sort_window=1",), "dispatch.sort_window"),
    ],
)
def test_bad_settings_are_named(
    sim_exe: Path, small_cornell_rays: Path, tmp_path: Path, sets: tuple[str, ...], named: str
) -> None:
    result = simulate(sim_exe, small_cornell_rays / "trace.rtt", tmp_path / "run", *sets)
    assert result.returncode == 2, result.stderr
    assert named in result.stderr


@pytest.mark.parametrize("accel", ["bvh4", "cwbvh8", "grid"])
def test_simt_on_every_structure_kind(sim_exe: Path, tmp_path: Path, accel: str) -> None:
    """Lanes drive any structure's steppers (wide nodes, compressed nodes, grid cells)."""
    trace = tmp_path / "trace"
    kinds = "primary,diffuse"
    rtsim.trace_scene("cornell", trace, workload=kinds, width=24, height=16, accel=accel)
    stats = sim_stats(
        sim_exe, trace / "trace.rtt", tmp_path / "run", *SIMT, "traversal.simt.lanes=16"
    )
    s = stats["summary"]
    assert s["hit_mismatches"] == 0 and s["work_mismatches"] == 0 and s["rays"] > 0
    assert 0.0 < s["simd_efficiency"] <= 1.0


def test_simt_two_level_with_frames(sim_exe: Path, tmp_path: Path) -> None:
    """Instance transforms are one more operation kind; frames hold warps at the barrier."""
    trace = tmp_path / "trace"
    rtsim.trace_scene("grove", trace, workload="primary", width=24, height=16, frames=3)
    stats = sim_stats(sim_exe, trace / "trace.rtt", tmp_path / "run", *SIMT)
    s = stats["summary"]
    assert s["hit_mismatches"] == 0 and s["work_mismatches"] == 0
    assert 0.0 < s["simd_efficiency"] <= 1.0
    assert len(stats["frames"]) == 3


def test_simt_sampled(sim_exe: Path, small_cornell_rays: Path, tmp_path: Path) -> None:
    small = ("traversal.model=simt", "traversal.units=2", "traversal.ray_contexts=16")
    stats = sim_stats(
        sim_exe, small_cornell_rays / "trace.rtt", tmp_path / "run", *small, "sampling.fraction=0.3"
    )
    s = stats["summary"]
    assert s["sampled"] is True and s["hit_mismatches"] == 0 and s["work_mismatches"] == 0
    assert 0.0 < s["simd_efficiency"] <= 1.0


def test_simt_alpha_instances_and_shadow_rays(
    sim_exe: Path, tmp_path: Path, scenes_dir: Path
) -> None:
    """Alpha tests (operations a step's results call for), instance transforms and any-hit
    shadow rays all run in lock-step with every hit and every ray's work checked."""
    alpha = tmp_path / "alpha"
    gltf = scenes_dir / "AlphaBlendModeTest" / "AlphaBlendModeTest.gltf"
    rtsim.trace_scene(str(gltf), alpha, width=24, height=16)
    shadows = tmp_path / "shadows"
    rtsim.trace_scene("cornell", shadows, workload="primary,shadow", width=24, height=16)
    for trace in (alpha, shadows):
        stats = sim_stats(sim_exe, trace / "trace.rtt", tmp_path / trace.name, *SIMT)
        s = stats["summary"]
        assert s["hit_mismatches"] == 0 and s["work_mismatches"] == 0
        built = {b["block"]: b["instantiated"] for b in stats["instantiated"]}
        if trace is alpha:
            assert built["anyhit"] and built["instance_transform"]
        else:
            assert stats["workload"]["occlusion_rays"] > 0


def test_execution_models_sweep_spec_parses() -> None:
    """The knobs are sweep axes: the shipped spec crosses model, lanes and sort."""
    from rtsim.sweep.spec import load_spec

    spec = load_spec(REPO / "python" / "rtsim" / "specs" / "execution_models.yaml")
    assert len(spec.points()) == 2 * 3 * 2


def test_simt_is_deterministic(sim_exe: Path, small_cornell_rays: Path, tmp_path: Path) -> None:
    """Same trace and config: the same model figures, run after run (rule 9)."""
    sets = (*SIMT, "dispatch.sort=morton", "traversal.simt.policy=if_if")
    trace = small_cornell_rays / "trace.rtt"
    runs = [sim_stats(sim_exe, trace, tmp_path / f"r{i}", *sets) for i in range(2)]
    assert runs[0]["model"] == runs[1]["model"]
    assert runs[0]["summary"]["cycles"] == runs[1]["summary"]["cycles"]
    assert runs[0]["summary"]["simd_efficiency"] == runs[1]["summary"]["simd_efficiency"]


@pytest.mark.parametrize(
    "sets",
    [
        ("traversal.simt.refill=lane",),
        ("traversal.simt.refill=warp",),
        ("traversal.simt.refill=lane", "fidelity=detailed"),
        ("traversal.simt.lanes=16", "treelets.prefetch=true", "treelets.policy=oldest"),
    ],
)
def test_simt_with_treelets_hands_every_ray_out_once(
    sim_exe: Path, small_cornell_rays: Path, tmp_path: Path, sets: tuple[str, ...]
) -> None:
    """Warps formed from one treelet queue's rays: every ray is admitted once, each take hands
    one waiting ray to one lane, every ray retires once, and hits and work match the reference."""
    stats = sim_stats(
        sim_exe, small_cornell_rays / "trace.rtt", tmp_path / "run", *SIMT, "treelets.enabled=true",
        "treelets.treelet_kib=2", *sets,
    )  # fmt: skip
    s = stats["summary"]
    assert s["hit_mismatches"] == 0 and s["work_mismatches"] == 0
    units = stats["model"]["units"].values()
    buffer = stats["model"]["ray_buffer"]
    assert sum(u["rays"] for u in units) == s["rays"] == buffer["admitted"]
    assert (
        sum(u["rays_taken"] for u in units)
        == buffer["taken"]
        == buffer["admitted"] + buffer["parked"]
    )
    assert sum(u["rays_parked"] for u in units) == buffer["parked"] > 0
    assert 0.0 < s["simd_efficiency"] <= 1.0


@pytest.mark.parametrize("model", ["simt", "packet"])
def test_the_analytic_level_costs_lock_step_groups(
    sim_exe: Path, small_cornell_rays: Path, tmp_path: Path, model: str
) -> None:
    """The analytic level prices warps and packets from the kind's functional group profile:
    its sampled rays are checked, its SIMD efficiency is the groups' and its scheduler takes
    group steps (fewer than a MIMD machine's ray steps)."""
    trace = small_cornell_rays / "trace.rtt"
    mimd = sim_stats(
        sim_exe, trace, tmp_path / "mimd", "fidelity=analytic", "traversal.ray_contexts=32"
    )
    stats = sim_stats(
        sim_exe, trace, tmp_path / "run", "fidelity=analytic", f"traversal.model={model}",
        "traversal.ray_contexts=32",
    )  # fmt: skip
    s = stats["summary"]
    assert s["hit_mismatches"] == 0 and s["work_mismatches"] == 0
    assert 0.0 < s["simd_efficiency"] < 1.0
    steps = sum(u["steps"] for u in stats["model"]["units"].values())
    assert steps < sum(u["steps"] for u in mimd["model"]["units"].values())
    assert s["cycles"] > mimd["summary"]["cycles"]  # lanes idle, group steps wait for the slowest
