"""Two-level structures through the whole chain: instanced scenes (the shared ones and the
procedural grove) traced two-level by default
(a BLAS per mesh geometry, a TLAS over the instances) and with `--flatten`; `rtsim-sim` replays the
two-level traces at every fidelity level with 0 hit and 0 work mismatches and a transform
pipeline; primary rays hit the same primitives and instances as the flattened trace.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import rtsim
from conftest import run_rtsim, sim_stats

SCENES = ["SimpleInstancing", "MetalRoughSpheresNoTextures", "grove"]  # grove: procedural
KINDS = ["bvh2", "bvh8"]
CONFIGS = {
    "functional": ["fidelity=functional"],
    "analytic": ["fidelity=analytic"],
    "approx": [],
    "detailed": ["fidelity=detailed"],
    "treelets": ["treelets.enabled=true", "treelets.treelet_kib=1"],
    "stack_spills": ["traversal.stack_entries=1"],
    "shared_transform": ["transform.sharing=shared", "transform.shared_count=1"],
}
RESOLUTION, WORKLOAD = "32x24", "primary,shadow,reflection,diffuse"


@pytest.fixture(scope="module")
def trace_of(
    tmp_path_factory: pytest.TempPathFactory, scenes_dir: Path
) -> Callable[[str, str, bool], Path]:
    """trace_of(scene, kind, flatten): each scene traced once per structure and mode."""
    root = tmp_path_factory.mktemp("two_level_traces")
    made: dict[tuple[str, str, bool], Path] = {}

    def trace(scene: str, kind: str, flatten: bool) -> Path:
        key = (scene, kind, flatten)
        if key not in made:
            out = root / f"{scene}-{kind}-{'flat' if flatten else 'two'}"
            gltf = scene if scene == "grove" else str(scenes_dir / scene / f"{scene}.gltf")
            args = ["trace", gltf, "-o", str(out), "--accel", kind, "--workload", WORKLOAD,
                    "--resolution", RESOLUTION, "--bounces", "1"]  # fmt: skip
            result = run_rtsim(*args, *(["--flatten"] if flatten else []))
            assert result.returncode == 0, result.stderr
            made[key] = out
        return made[key]

    return trace


@pytest.mark.parametrize("scene", SCENES)
@pytest.mark.parametrize("kind", KINDS)
def test_instanced_scenes_trace_two_level_by_default(
    trace_of: Callable[[str, str, bool], Path], scene: str, kind: str
) -> None:
    two = json.loads((trace_of(scene, kind, False) / "manifest.json").read_text())["accel"]
    flat = json.loads((trace_of(scene, kind, True) / "manifest.json").read_text())["accel"]
    assert two["kind"] == "two_level" and two["blas_kind"] == kind
    assert two["instances"] > two["blases"] >= 1
    assert flat["kind"] == kind
    work = rtsim.open_trace(trace_of(scene, kind, False)).work
    assert int(work["transforms"].sum()) > 0


@pytest.mark.parametrize("scene", SCENES)
@pytest.mark.parametrize("kind", KINDS)
def test_primary_hits_equal_the_flattened_trace(
    trace_of: Callable[[str, str, bool], Path], scene: str, kind: str
) -> None:
    two = rtsim.open_trace(trace_of(scene, kind, False))
    flat = rtsim.open_trace(trace_of(scene, kind, True))
    p2, pf = two.rays["depth"] == 0, flat.rays["depth"] == 0
    rays2, raysf = two.rays[p2], flat.rays[pf]
    assert len(rays2) == len(raysf) > 0
    assert np.array_equal(rays2["origin"], raysf["origin"])
    assert np.array_equal(rays2["direction"], raysf["direction"])
    h2, hf = two.hits[p2], flat.hits[pf]
    assert np.array_equal(h2["prim"], hf["prim"])
    assert np.array_equal(h2["inst"], hf["inst"])
    hit = hf["prim"] >= 0
    assert hit.any()
    np.testing.assert_allclose(h2["t"][hit], hf["t"][hit], rtol=1e-5)


@pytest.mark.parametrize("config", list(CONFIGS))
@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("scene", SCENES)
def test_model_replays_two_level_traces(
    trace_of: Callable[[str, str, bool], Path],
    sim_exe: Path,
    tmp_path: Path,
    scene: str,
    kind: str,
    config: str,
) -> None:
    trace = trace_of(scene, kind, False)
    stats = sim_stats(sim_exe, trace, tmp_path / "run", *CONFIGS[config])
    summary, validation = stats["summary"], stats["validation"]
    assert summary["rays"] == validation["rays_checked"] == len(rtsim.open_trace(trace).rays) > 0
    assert summary["hit_mismatches"] == 0, validation["first_mismatches"]
    assert summary["work_mismatches"] == 0, validation["first_mismatches"]
    if config not in ("functional", "analytic"):  # the timed model builds blocks
        built = {b["block"]: b["instantiated"] for b in stats["instantiated"]}
        assert built["instance_transform"]
    if config in ("approx", "detailed", "shared_transform"):
        # The transform pipeline ran one test per instance the reference entered.
        tests = sum(p["tests"] for p in stats["model"]["transform"].values())
        assert tests == int(rtsim.open_trace(trace).work["transforms"].sum()) > 0


def test_scene_exposes_its_instances(scenes_dir: Path) -> None:
    scene = rtsim.load_scene(scenes_dir / "SimpleInstancing" / "SimpleInstancing.gltf")
    instances = scene.instances
    assert len(instances) == scene.instance_count == 125
    assert [i["prim_base"] for i in instances] == [12 * k for k in range(125)]
    matrices = np.array([i["object_to_world"] for i in instances])
    assert matrices.shape == (125, 4, 4)
    assert np.allclose(matrices[:, 3], [0, 0, 0, 1])
    assert (np.abs(np.linalg.det(matrices[:, :3, :3])) > 0).all()
