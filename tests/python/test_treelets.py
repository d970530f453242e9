"""Treelet scheduling end to end: no ray lost or duplicated under any policy or under
overflow, the ray buffer never holds more than its capacity, overflow traffic is counted as
ray_buffer bytes, and on incoherent rays treelets cut DRAM traffic. Hit equality with and without
treelets on every scene is in test_model.py (CONFIGS "treelets*")."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from conftest import rtsim_trace, sim_or_fail, sim_stats


@pytest.fixture(scope="module")
def hairball_diffuse(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("treelets") / "hairball_diffuse"
    rtsim_trace(
        "hairball", "-o", str(out), "--workload", "diffuse",
        "--resolution", "256x192", "--hairball-triangles", "60000",
    )  # fmt: skip
    return out


def simulate(trace: Path, out: Path, *sets: str) -> dict[str, Any]:
    return sim_stats(sim_or_fail(), trace, out, *sets)


# (buffer KiB, rays admitted at once: 0 = what the SRAM and contexts hold, never overflowing)
BUFFERS = [(1, 0), (1, 2000), (16, 0), (16, 600), (1024, 0)]


@pytest.mark.parametrize("policy", ["largest", "oldest", "round_robin"])
@pytest.mark.parametrize(("buffer_kib", "in_flight"), BUFFERS)
def test_no_ray_lost_or_duplicated_and_capacity_kept(
    hairball_diffuse: Path, tmp_path: Path, policy: str, buffer_kib: int, in_flight: int
) -> None:
    stats = simulate(
        hairball_diffuse, tmp_path / "run", "treelets.enabled=true",
        f"treelets.policy={policy}", f"treelets.buffer_kib={buffer_kib}",
        f"treelets.max_rays_in_flight={in_flight}",
    )  # fmt: skip
    validation, buffer = stats["validation"], stats["model"]["ray_buffer"]
    # Every ray finished exactly once (a second completion is an error in rtsim-sim itself).
    assert validation["rays_checked"] == validation["rays_expected"] == stats["summary"]["rays"]
    assert validation["hit_mismatches"] == 0 and validation["work_mismatches"] == 0
    assert buffer["admitted"] == stats["summary"]["rays"]
    assert buffer["taken"] == buffer["admitted"] + buffer["parked"]
    assert buffer["max_occupancy"] <= buffer["capacity_rays"]
    if in_flight == 0:
        assert buffer["overflow_writes"] == 0  # by default nothing overflows
    elif in_flight > 100 * buffer_kib:
        # Far more rays admitted than the SRAM holds: queues overflow, and the traffic is counted.
        assert buffer["overflow_writes"] > 0
        assert buffer["overflow_reads"] == buffer["overflow_writes"]
        dram = stats["model"]["dram"]["by_kind"]["ray_buffer"]
        assert dram["write_bytes"] == buffer["overflow_writes"] * buffer["ray_state_bytes"]
        # Reads of overflowed states go through the L2 (slots are reused, so many hit there).
        l2 = stats["model"]["l2"]["by_kind"]["ray_buffer"]
        assert l2["reads"] >= buffer["overflow_reads"]


def test_treelets_cut_dram_traffic_on_incoherent_rays(
    hairball_diffuse: Path, tmp_path: Path
) -> None:
    # A small L2 so the hairball's BVH does not fit on chip: the case treelets exist for.
    small_l2 = ("l2.size_kib=128",)
    base = simulate(hairball_diffuse, tmp_path / "base", *small_l2)
    treelets = simulate(
        hairball_diffuse, tmp_path / "treelets", *small_l2, "treelets.enabled=true",
        "treelets.buffer_kib=1024",
    )  # fmt: skip
    base_bvh = sum(base["model"]["dram"]["by_kind"][k]["read_bytes"] for k in ("node", "triangle"))
    treelet_bvh = sum(
        treelets["model"]["dram"]["by_kind"][k]["read_bytes"] for k in ("node", "triangle")
    )
    # Measured: about half (32.1 MB -> 15.8 MB of BVH reads, 12,917 rays).
    assert treelet_bvh < 0.7 * base_bvh, (treelet_bvh, base_bvh)


def test_stats_report_the_partition(hairball_diffuse: Path, tmp_path: Path) -> None:
    stats = simulate(hairball_diffuse, tmp_path / "run", "treelets.enabled=true")
    part = stats["model"]["ray_buffer"]["treelets"]
    assert part["count"] > 1
    assert part["max_bytes"] <= part["budget_bytes"] or part["count"] == 1
    blocks = {b["block"]: b for b in stats["instantiated"]}
    assert blocks["ray_buffer"]["instantiated"] is True
    assert "treelets" in blocks["ray_buffer"]["why"]


def test_the_analytic_level_steps_its_sample_in_treelet_order(
    hairball_diffuse: Path, tmp_path: Path
) -> None:
    """At the analytic level treelet scheduling orders the sample's steps (the ray buffer run
    functionally), so treelets cut the BVH's DRAM traffic there too, and the ray buffer's SRAM
    port is a bound; every sampled ray is checked."""
    small_l2 = ("l2.size_kib=128", "fidelity=analytic")
    base = simulate(hairball_diffuse, tmp_path / "base", *small_l2)
    treelets = simulate(
        hairball_diffuse, tmp_path / "treelets", *small_l2, "treelets.enabled=true",
        "treelets.buffer_kib=1024",
    )  # fmt: skip
    assert treelets["validation"]["hit_mismatches"] == 0
    assert treelets["validation"]["work_mismatches"] == 0
    assert "ray_buffer" in treelets["model"]["analytic"]["bounds"]
    bvh = [
        sum(s["model"]["dram"]["by_kind"][k]["read_bytes"] for k in ("node", "triangle"))
        for s in (base, treelets)
    ]
    assert bvh[1] < 0.8 * bvh[0], bvh
