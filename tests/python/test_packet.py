"""Packets (traversal.model=packet, Wald et al. 2001), on the binary and the wide BVHs and the
space-partitioning structures: every hit
identical to single-ray traversal and every ray's work equal to the reference packet loop's, at
every timed level and functional, with and without sorting and with the hybrid's split into
single rays; occupancy exactly 1 when every ray of a packet is the same ray; one node fetch
serves a packet; lanes' cycles accounted; structures without a packet kernel and bad settings
refused, naming the field."""

from __future__ import annotations

from pathlib import Path

import pytest

import rtsim
from conftest import sim_stats, simulate

PACKET = ("traversal.model=packet", "traversal.ray_contexts=64")


@pytest.mark.parametrize(
    "sets",
    [
        ("traversal.packet.lanes=4",),
        ("traversal.packet.lanes=16", "fidelity=detailed"),
        ("traversal.packet.lanes=64", "traversal.stack_entries=2"),
        ("traversal.packet.lanes=16", "dispatch.sort=origin_direction"),
        ("traversal.packet.lanes=16", "fidelity=functional"),
        ("traversal.packet.lanes=16", "traversal.packet.split_below=0.5"),
        ("traversal.packet.lanes=64", "traversal.packet.split_below=0.25", "fidelity=functional"),
    ],
)
def test_packet_hits_and_work_match_the_reference(
    sim_exe: Path, small_cornell_rays: Path, tmp_path: Path, sets: tuple[str, ...]
) -> None:
    stats = sim_stats(sim_exe, small_cornell_rays / "trace.rtt", tmp_path / "run", *PACKET, *sets)
    s = stats["summary"]
    assert s["hit_mismatches"] == 0 and s["work_mismatches"] == 0
    assert s["rays"] == rtsim.open_trace(small_cornell_rays).manifest["counts"]["rays"]
    if "fidelity=functional" in sets:
        return
    lanes = int(next(x for x in sets if x.startswith("traversal.packet.lanes=")).split("=")[1])
    units = stats["model"]["units"].values()
    assert sum(u["rays"] for u in units) == s["rays"]
    assert 0.0 < s["simd_efficiency"] < 1.0  # diffuse rays leave the packet's path
    for u in units:
        assert u["lane_slots"] == u["packet_steps"] * lanes
        assert sum(u["packet_active_histogram"]) == u["packet_steps"]
        assert sum(k * n for k, n in enumerate(u["packet_active_histogram"])) == u["active_lanes"]
        assert u["packet_active_histogram"][0] == 0  # a step always has a ray in it
        assert u["packet_occupancy"] == pytest.approx(u["active_lanes"] / u["packet_steps"])
        assert u["packets"] * lanes >= u["rays"] > (u["packets"] - 1) * 1
        assert u["node_fetches_per_packet"] == pytest.approx(
            u["packet_node_fetches"] / u["packets"]
        )
        if "traversal.stack_entries=2" in sets:
            assert u["stack_spill_writes"] > 0
        split = any(x.startswith("traversal.packet.split_below") for x in sets)
        assert (u["packet_splits"] > 0) == split
        assert (u["packet_split_steps"] > 0) == split
    acc = stats["model"]["cycle_accounting"]
    assert acc["context_cycles"] == 8 * 64 * s["cycles"]
    assert sum(acc["by_use"].values()) == acc["context_cycles"]
    assert acc["by_use"]["idle_lane"] > 0


def test_packets_share_node_fetches(
    sim_exe: Path, small_cornell_rays: Path, tmp_path: Path
) -> None:
    """A packet's node step is one fetch: far fewer node reads than single rays make."""
    mimd = sim_stats(
        sim_exe, small_cornell_rays / "trace.rtt", tmp_path / "mimd", "traversal.ray_contexts=64"
    )
    pk = sim_stats(
        sim_exe,
        small_cornell_rays / "trace.rtt",
        tmp_path / "pk",
        *PACKET,
        "traversal.packet.lanes=16",
    )
    node_reads = sum(u["packet_node_fetches"] for u in pk["model"]["units"].values())
    # A MIMD unit's scheduler steps: 2 per traversal step and 1 per ray.
    single_steps = sum(u["steps"] for u in mimd["model"]["units"].values())
    assert node_reads < single_steps / 2 / 4
    # Each ray's box tests are its own: packets never test fewer boxes than single rays.
    assert pk["summary"]["work_mismatches"] == 0


def test_occupancy_is_one_when_every_ray_of_a_packet_is_the_same_ray_trace(
    sim_exe: Path, same_ray_trace: Path, tmp_path: Path
) -> None:
    for lanes in (4, 8, 16):
        stats = sim_stats(
            sim_exe,
            same_ray_trace / "trace.rtt",
            tmp_path / f"l{lanes}",
            "traversal.model=packet",
            "traversal.units=1",
            "traversal.ray_contexts=32",
            f"traversal.packet.lanes={lanes}",
        )
        s = stats["summary"]
        assert s["hit_mismatches"] == 0 and s["work_mismatches"] == 0
        assert s["simd_efficiency"] == 1.0
        unit = stats["model"]["units"]["tu0"]
        assert unit["packet_occupancy"] == float(lanes)
        assert unit["packets"] == 128 // lanes
        assert unit["packet_active_histogram"][:lanes] == [0] * lanes
        assert "idle_lane" not in stats["model"]["cycle_accounting"]["by_use"]
        # The packet walks the single ray's path: one node fetch per single-ray node step.
        steps = int(rtsim.open_trace(same_ray_trace).work["steps"][0])
        assert unit["packet_node_fetches"] == steps * unit["packets"]


@pytest.mark.parametrize("accel", ["kdtree", "bih", "bkd", "octree", "grid"])
def test_packets_on_space_partitioning_structures(
    sim_exe: Path, tmp_path: Path, accel: str
) -> None:
    """Packets, the hybrid on lanes and mailboxes on the kd-tree, BIH, B-Kd tree, octree and
    grid replay with every ray's hit and work equal to each structure's reference packet loop."""
    trace = tmp_path / "trace"
    rtsim.trace_scene("cornell", trace, workload="primary,diffuse", width=12, height=9, accel=accel)
    mailbox = [] if accel in ("bih", "bkd") else ["mailbox.entries=8"]  # no duplicates: none
    for i, sets in enumerate(
        [
            [],
            ["traversal.packet.split_below=0.5", "traversal.packet.split_walks=lanes"],
            ["traversal.packet.lanes=4", *mailbox],
            ["fidelity=functional"],
        ]
    ):
        stats = sim_stats(sim_exe, trace / "trace.rtt", tmp_path / f"run{i}", *PACKET, *sets)
        s = stats["summary"]
        assert s["hit_mismatches"] == 0 and s["work_mismatches"] == 0, (accel, sets)
        assert s["rays"] == rtsim.open_trace(trace).manifest["counts"]["rays"]


@pytest.fixture(scope="module")
def wide_cornell_traces(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Cornell primary and diffuse rays at 24x18 on the wide BVHs with a packet kernel."""
    root = tmp_path_factory.mktemp("wide_cornell")
    out = {}
    for accel in ("bvh4", "bvh8", "cwbvh8", "cwbvh8_octant"):
        out[accel] = root / accel
        rtsim.trace_scene(
            "cornell", out[accel], workload="primary,diffuse", width=24, height=18, accel=accel
        )
    return out


@pytest.mark.parametrize("accel", ["bvh4", "bvh8", "cwbvh8", "cwbvh8_octant"])
@pytest.mark.parametrize(
    "sets",
    [
        ("traversal.packet.lanes=16",),
        ("traversal.packet.lanes=16", "traversal.packet.split_below=0.5", "box.width=16"),
        ("traversal.packet.lanes=8", "fidelity=functional"),
    ],
)
def test_packets_on_wide_bvhs_match_the_reference(
    sim_exe: Path,
    wide_cornell_traces: dict[str, Path],
    tmp_path: Path,
    accel: str,
    sets: tuple[str, ...],
) -> None:
    """Packets on 4- and 8-wide nodes, fp32 and compressed: every hit the trace's, every ray's
    work the reference packet loop's; a packet step fetches one node for its rays."""
    trace = wide_cornell_traces[accel] / "trace.rtt"
    stats = sim_stats(sim_exe, trace, tmp_path / "run", *PACKET, *sets)
    s = stats["summary"]
    assert s["hit_mismatches"] == 0 and s["work_mismatches"] == 0
    assert s["rays"] == rtsim.open_trace(wide_cornell_traces[accel]).manifest["counts"]["rays"]
    if "fidelity=functional" in sets:
        return
    units = stats["model"]["units"].values()
    node_fetches = sum(u["packet_node_fetches"] for u in units)
    assert 0 < node_fetches < sum(u["packet_steps"] for u in units)
    assert 0.0 < s["simd_efficiency"] < 1.0
    if any(x.startswith("traversal.packet.split_below") for x in sets):
        assert sum(u["packet_splits"] for u in units) > 0


@pytest.mark.parametrize(
    ("sets", "named"),
    [
        (
            ("traversal.model=packet", "traversal.packet.split_below=1.5"),
            "traversal.packet.split_below",
        ),
        (("traversal.model=packet", "traversal.packet.lanes=2"), "traversal.packet.lanes"),
        (
            ("traversal.model=packet", "traversal.ray_contexts=20", "traversal.packet.lanes=16"),
            "traversal.ray_contexts",
        ),
    ],
)
def test_bad_packet_settings_are_named(
    sim_exe: Path, small_cornell_rays: Path, tmp_path: Path, sets: tuple[str, ...], named: str
) -> None:
    result = simulate(sim_exe, small_cornell_rays / "trace.rtt", tmp_path / "run", *sets)
    assert result.returncode == 2, result.stderr
    assert named in result.stderr
