"""Every wide and compressed BVH through the whole chain: `rtsim trace --accel KIND` on a small
scene, then `rtsim-sim` at each fidelity level and a few configurations, with 0 hit and 0 work
mismatches; the traces' hits equal the binary BVH's bit for bit; the box pipeline runs one test
per child and ceil(children / width) issues per node; the manifest records the structure.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import rtsim
from conftest import rtsim_trace, sim_stats

KINDS = ["bvh4", "bvh6", "bvh8", "cwbvh6", "cwbvh8", "bvh8_octant", "cwbvh8_octant"]
NODE_BYTES = {"bvh4": 128, "bvh6": 192, "bvh8": 256, "cwbvh6": 64, "cwbvh8": 80}
CONFIGS = {
    "functional": ["fidelity=functional"],
    "analytic": ["fidelity=analytic"],
    "approx": [],
    "detailed": ["fidelity=detailed"],
    "treelets": ["treelets.enabled=true", "treelets.treelet_kib=1"],
    "stack_spills": ["traversal.stack_entries=1"],
}
SCENE, RESOLUTION, WORKLOAD = "cornell", "32x24", "primary,shadow,reflection,diffuse"


@pytest.fixture(scope="module")
def trace_of(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str], Path]:
    """trace_of(kind): the small scene traced once per structure."""
    root = tmp_path_factory.mktemp("accel_traces")
    made: dict[str, Path] = {}

    def trace(kind: str) -> Path:
        if kind not in made:
            out = root / kind
            rtsim_trace(
                SCENE, "-o", str(out), "--accel", kind, "--workload", WORKLOAD,
                "--resolution", RESOLUTION, "--bounces", "1",
            )  # fmt: skip
            made[kind] = out
        return made[kind]

    return trace


@pytest.mark.parametrize("config", list(CONFIGS))
@pytest.mark.parametrize("kind", KINDS)
def test_model_replays_every_structure(
    trace_of: Callable[[str], Path], sim_exe: Path, tmp_path: Path, kind: str, config: str
) -> None:
    trace = trace_of(kind)
    stats = sim_stats(sim_exe, trace, tmp_path / "run", *CONFIGS[config])
    summary, validation = stats["summary"], stats["validation"]
    assert summary["rays"] == validation["rays_checked"] == len(rtsim.open_trace(trace).rays) > 0
    assert summary["hit_mismatches"] == 0, validation["first_mismatches"]
    assert summary["work_mismatches"] == 0, validation["first_mismatches"]


@pytest.mark.parametrize("kind", KINDS)
def test_hits_equal_the_binary_bvh(trace_of: Callable[[str], Path], kind: str) -> None:
    ours, binary = rtsim.open_trace(trace_of(kind)), rtsim.open_trace(trace_of("bvh2"))
    assert np.array_equal(ours.rays, binary.rays)  # the same rays: secondaries follow hits
    # Closest hits bit for bit; any-hit (occlusion) rays stop at the first hit the order finds,
    # so only hit or miss must agree.
    any_hit = (np.asarray(ours.rays["flags"]) & 1) == 1
    assert 0 < any_hit.sum() < len(any_hit)
    closest = ~any_hit
    assert np.array_equal(ours.hits[closest].view(np.uint32), binary.hits[closest].view(np.uint32))
    assert np.array_equal(ours.hits["prim"][any_hit] >= 0, binary.hits["prim"][any_hit] >= 0)
    manifest = json.loads((trace_of(kind) / "manifest.json").read_text())["accel"]
    assert manifest["kind"] == kind
    assert manifest["node_bytes"] == NODE_BYTES[kind.removesuffix("_octant")]
    assert manifest["width"] == int(kind.removesuffix("_octant")[-1])
    assert manifest["footprint_bytes"] > 0 and manifest["sah_cost"] > 0
    nodes = ours.nodes  # read through the layout's dtype (rtsim.trace_file.REGION_DTYPES)
    assert nodes is not None and nodes.dtype.names is not None
    assert nodes.dtype.itemsize == manifest["node_bytes"] and len(nodes) == manifest["nodes"]


@pytest.mark.parametrize(("kind", "width"), [("bvh8", 8), ("bvh8", 1), ("cwbvh6", 4), ("bvh4", 2)])
def test_box_pipeline_tests_each_child_and_issues_per_width(
    trace_of: Callable[[str], Path], sim_exe: Path, tmp_path: Path, kind: str, width: int
) -> None:
    trace = trace_of(kind)
    stats = sim_stats(sim_exe, trace, tmp_path / "run", f"box.width={width}")
    pipes = stats["model"]["box"].values()
    tests, issues = sum(p["tests"] for p in pipes), sum(p["issues"] for p in pipes)
    work = rtsim.open_trace(trace).work
    assert tests == int(work["box_tests"].sum()) > 0
    steps = int(work["steps"].sum())
    if width >= int(kind[-1]):
        assert issues == steps  # every node fits one issue
    elif width == 1:
        assert issues == tests
    else:
        assert steps < issues < tests
