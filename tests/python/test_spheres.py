"""Spheres (docs/accel.md, "Spheres"): the sphere scenes trace on the BVH kinds and replay with
zero mismatches at every level and execution model, their sphere tests going to the sphere
pipeline; glTF POINTS with _RADIUS is the way in, and bad input is refused naming the culprit;
structures that cannot store spheres refuse them naming those that can; the study runs."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import rtsim
from conftest import checked, run_rtsim
from rtsim.tracing import RAY_KINDS


@pytest.fixture(scope="module", params=["bvh2", "cwbvh8"])
def trace(tmp_path_factory: pytest.TempPathFactory, request: pytest.FixtureRequest) -> Path:
    out = tmp_path_factory.mktemp("spheres") / f"particles-{request.param}"
    made = run_rtsim("trace", "particles", "-o", str(out), "--resolution", "24x18",
                     "--accel", request.param)  # fmt: skip
    assert made.returncode == 0, made.stderr
    return out


def test_manifest_counts_spheres_and_their_tests(trace: Path) -> None:
    m = json.loads((trace / "manifest.json").read_text())
    assert m["scene"]["spheres"] == 40001 and m["scene"]["triangles"] == 2
    assert m["trace_version"] == 6
    kinds = m["counts"]["by_kind"]
    assert set(kinds) >= {"primary", "shadow", "diffuse"}
    assert kinds["primary"]["sphere_tests_per_ray"] > 0
    t = rtsim.open_trace(trace)
    assert t.work["sphere_tests"].sum() > 0
    # The image's sphere records: flag bit 1, centre and radius (docs/bvh_layout.md).
    tris = t.triangles
    spheres = tris[(tris["flags"] & 2) != 0]
    assert len(spheres) == 40001
    assert (spheres["v1"][:, 0] >= 0.006).all() and (spheres["v2"] == 0).all()


@pytest.mark.parametrize(
    "sets",
    [
        ["fidelity=functional"],
        ["fidelity=approx"],
        ["fidelity=detailed"],
        ["fidelity=analytic"],
        ["traversal.model=simt"],
        ["traversal.model=packet"],
        ["treelets.enabled=true"],
    ],
)
def test_replays_with_zero_mismatches(
    trace: Path, sim_exe: Path, tmp_path: Path, sets: list[str]
) -> None:
    stats = checked(sim_exe, trace, tmp_path / "run", *sets)
    if "fidelity=functional" not in sets:
        blocks = {b["block"]: b for b in stats["instantiated"]}
        assert blocks["sphere"]["instantiated"], blocks["sphere"]
        assert stats["area"]["mm2"]["sphere"] > 0
        assert stats["energy"]["per_ray_nj"]["sphere"] > 0
        tests = sum(p["tests"] for p in stats["model"]["sphere"].values())
        t = rtsim.open_trace(trace)
        if "traversal.model=packet" not in sets:
            assert tests == int(np.asarray(t.work["sphere_tests"]).sum())


def test_triangle_scenes_build_no_sphere_pipeline(sim_exe: Path, tmp_path: Path) -> None:
    out = tmp_path / "cornell"
    assert run_rtsim("trace", "cornell", "-o", str(out), "--resolution", "8x6").returncode == 0
    stats = checked(sim_exe, out, tmp_path / "run")
    blocks = {b["block"]: b for b in stats["instantiated"]}
    assert not blocks["sphere"]["instantiated"]
    assert "sphere" not in stats["area"]["mm2"]


def test_structures_that_clip_refuse_spheres(tmp_path: Path) -> None:
    made = run_rtsim("trace", "furball", "-o", str(tmp_path / "kd"), "--resolution", "8x6",
                     "--accel", "kdtree")  # fmt: skip
    assert made.returncode != 0
    assert (
        "the scene has curved primitives (spheres or capsules), which accel kdtree cannot store"
        in made.stderr
    ), made.stderr
    assert "bvh2, bvh4" in made.stderr
    made = run_rtsim("trace", "furball", "-o", str(tmp_path / "sbvh"), "--resolution", "8x6",
                     "--builder", "sbvh")  # fmt: skip
    assert made.returncode != 0 and "sbvh builder clips" in made.stderr, made.stderr


def _points_gltf(
    folder: Path, radius: list[float] | None, mode: int = 0, nodes: list[dict] | None = None
) -> Path:
    """A glTF of two points (spheres when `radius` is given as their _RADIUS), or of the
    segment between them (a capsule) for a LINES mode, placed by `nodes` (one node scaled by 2
    when None)."""
    folder.mkdir(parents=True, exist_ok=True)
    pos = np.array([[0, 0, 0], [3, 0, 0]], dtype=np.float32).tobytes()
    attributes = {"POSITION": 0}
    views = [{"buffer": 0, "byteOffset": 0, "byteLength": 24}]
    accessors = [{"bufferView": 0, "componentType": 5126, "count": 2, "type": "VEC3",
                  "min": [0, 0, 0], "max": [3, 0, 0]}]  # fmt: skip
    data = pos
    if radius is not None:
        data += np.array(radius, dtype=np.float32).tobytes()
        views.append({"buffer": 0, "byteOffset": 24, "byteLength": 8})
        accessors.append({"bufferView": 1, "componentType": 5126, "count": 2, "type": "SCALAR"})
        attributes["_RADIUS"] = 1
    (folder / "points.bin").write_bytes(data)
    gltf = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes or [0])))}],
        "nodes": nodes or [{"mesh": 0, "scale": [2, 2, 2]}],
        "meshes": [{"name": "beads", "primitives": [{"attributes": attributes, "mode": mode}]}],
        "buffers": [{"uri": "points.bin", "byteLength": len(data)}],
        "bufferViews": views,
        "accessors": accessors,
    }
    path = folder / "points.gltf"
    path.write_text(json.dumps(gltf))
    return path


def test_gltf_points_with_radius_are_spheres(tmp_path: Path) -> None:
    scene = rtsim._core.load_scene(str(_points_gltf(tmp_path / "ok", [0.5, 1.0])))
    tris = np.asarray(scene.triangles())
    # Flattened as {lo, hi, centre}: the node's scale of 2 moves the centre and scales the radius.
    assert np.allclose(tris[1, 2], [6, 0, 0]) and np.allclose(tris[1, 1], [8, 2, 2])
    out = tmp_path / "trace"
    gltf = str(tmp_path / "ok" / "points.gltf")
    made = run_rtsim("trace", gltf, "-o", str(out), "--resolution", "8x6",
                     "--camera", "3,0,-20,3,0,0,40")  # fmt: skip
    assert made.returncode == 0, made.stderr
    assert rtsim.open_trace(out).hits["prim"].max() >= 0


@pytest.mark.parametrize("mode", [1, 3])
def test_gltf_lines_with_radius_are_capsules(tmp_path: Path, mode: int) -> None:
    scene = rtsim._core.load_scene(str(_points_gltf(tmp_path, [0.5, 1.0], mode)))
    tris = np.asarray(scene.triangles())
    # One capsule (0,0,0)-(6,0,0) under the scale of 2, its radius from 1 to 2: its box is
    # its end spheres'.
    assert tris.shape == (1, 3, 3)
    assert np.allclose(tris[0, 0], [-1, -2, -2]) and np.allclose(tris[0, 1], [8, 2, 2])
    assert np.allclose(tris[0, 2], [3, 0, 0])


def test_capsules_replay_with_zero_mismatches(sim_exe: Path, tmp_path: Path) -> None:
    out = tmp_path / "fur"
    made = run_rtsim("trace", "furball_capsules", "-o", str(out), "--resolution", "24x18",
                     "--accel", "bvh8")  # fmt: skip
    assert made.returncode == 0, made.stderr
    m = json.loads((out / "manifest.json").read_text())
    assert m["scene"]["capsules"] == 16000 and m["scene"]["spheres"] == 1
    assert m["counts"]["by_kind"]["primary"]["capsule_tests_per_ray"] > 0
    for sets in (["fidelity=detailed"], ["fidelity=analytic"], ["traversal.model=simt"],
                 ["traversal.model=packet"]):  # fmt: skip
        stats = checked(sim_exe, out, tmp_path / sets[0].replace("=", "-"), *sets)
        assert stats["area"]["mm2"]["capsule"] > 0 and stats["energy"]["per_ray_nj"]["capsule"] > 0
        tests = sum(p["tests"] for p in stats["model"]["capsule"].values())
        assert tests > 0


@pytest.mark.parametrize(
    ("radius", "message"),
    [
        (None, "need a _RADIUS attribute"),
        ([0.5, 0.0], "has _RADIUS 0"),
        ([0.5, float("nan")], "has _RADIUS nan"),
    ],
)
def test_bad_points_are_refused_naming_the_culprit(
    tmp_path: Path, radius: list[float] | None, message: str
) -> None:
    path = _points_gltf(tmp_path, radius)
    with pytest.raises(rtsim.RtsimError) as err:
        rtsim._core.load_scene(str(path))
    assert "primitive 0" in str(err.value) and message in str(err.value), str(err.value)


def test_spheres_study_quick(tmp_path: Path) -> None:
    made = run_rtsim("study", "spheres", "--quick", "-o", str(tmp_path / "study"))
    assert made.returncode == 0, made.stderr
    assert "| particles | primary | bvh2 | 40,001 / 800,022 |" in made.stdout, made.stdout


def test_version_5_traces_open_with_zero_sphere_tests(trace: Path, tmp_path: Path) -> None:
    """A trace of version 5 (32-byte WORK records) opens in Python as in C++: this version's
    fields, sphere_tests 0, the others as stored."""
    from trace_forge import as_version_5_work, read_sections, write_trace

    sections = read_sections(trace / "trace.rtt")
    as_version_5_work(sections)
    folder = tmp_path / "v5"
    folder.mkdir()
    (folder / "manifest.json").write_text((trace / "manifest.json").read_text())
    write_trace(folder / "trace.rtt", sections, version=5)
    old, new = rtsim.open_trace(folder), rtsim.open_trace(trace)
    assert old.work.dtype == new.work.dtype and len(old.work) == len(new.work)
    assert (old.work["sphere_tests"] == 0).all()
    for field in ("steps", "box_tests", "tri_tests", "refs"):
        assert (old.work[field] == new.work[field]).all(), field


def test_verdict_offers_no_compressed_leaves_for_curved_scenes(
    trace: Path, sim_exe: Path, tmp_path: Path
) -> None:
    """Compressed leaves index triangle vertices (a sphere scene refuses them), so the verdict's
    structural alternatives leave them out; the other structures that store spheres stay."""
    stats = checked(sim_exe, trace, tmp_path / "run")
    keys = {k["key"] for k in stats["verdict"]["structural"]}
    assert "compressed_leaves" not in keys and "treelets.enabled" in keys


def test_instanced_capsules_trace_in_two_levels_and_replay(sim_exe: Path, tmp_path: Path) -> None:
    """furball_herd places one mesh of capsules nine times: a two-level structure whose BLAS
    holds the capsules in object space, replayed with zero mismatches by every execution model."""
    out = tmp_path / "herd"
    made = run_rtsim("trace", "furball_herd", "-o", str(out), "--resolution", "24x18")
    assert made.returncode == 0, made.stderr
    m = json.loads((out / "manifest.json").read_text())
    assert m["accel"]["kind"] == "two_level"
    assert m["scene"]["capsules"] == 9 * 16000 and m["scene"]["spheres"] == 9
    assert m["counts"]["by_kind"]["shadow"]["capsule_tests_per_ray"] > 0
    for sets in (["fidelity=detailed"], ["fidelity=analytic"], ["traversal.model=simt"],
                 ["traversal.model=packet"]):  # fmt: skip
        stats = checked(sim_exe, out, tmp_path / sets[0].replace("=", "-"), *sets)
        assert sum(p["tests"] for p in stats["model"]["capsule"].values()) > 0


def test_two_level_curved_hits_match_the_flattened_scene(tmp_path: Path) -> None:
    """Traced in object space under similarity transforms, the instances' capsules and spheres
    are hit where the flattened scene's world-space ones are (ties and grazes aside)."""
    hits = []
    for flag in ([], ["--flatten"]):
        out = tmp_path / ("flat" if flag else "two")
        made = run_rtsim("trace", "furball_herd", "-o", str(out), "--resolution", "48x36",
                         "--workload", "primary", *flag)  # fmt: skip
        assert made.returncode == 0, made.stderr
        hits.append(rtsim.open_trace(out).hits)
    two, flat = hits
    same = two["prim"] == flat["prim"]
    assert same.mean() > 0.999 and (two["prim"] >= 0).mean() > 0.3
    hit = same & (two["prim"] >= 0)
    assert np.allclose(two["t"][hit], flat["t"][hit], rtol=1e-4)


def test_instanced_spheres_under_a_non_uniform_scale_are_refused(tmp_path: Path) -> None:
    nodes = [{"mesh": 0}, {"mesh": 0, "translation": [0, 5, 0], "scale": [1, 2, 1]}]
    gltf = _points_gltf(tmp_path / "g", [0.5, 1.0], nodes=nodes)
    made = run_rtsim("trace", str(gltf), "-o", str(tmp_path / "t"), "--resolution", "8x6")
    assert made.returncode != 0 and "non-uniform scale" in made.stderr, made.stderr
    assert "node 1" in made.stderr


def test_deforming_capsules_refit_and_rebuild_with_the_same_hits(
    sim_exe: Path, tmp_path: Path
) -> None:
    """exploding_furball's capsules fly apart over frames: its BLAS refitted or rebuilt per
    frame, each replayed with zero mismatches; closest hits are the same under both policies, and
    any-hit rays agree on occlusion (which capsule they report may differ)."""
    traces = {}
    for policy in ("refit", "rebuild"):
        out = tmp_path / policy
        made = run_rtsim("trace", "exploding_furball", "-o", str(out), "--resolution", "24x18",
                         "--frames", "4", "--frame-policy", policy)  # fmt: skip
        assert made.returncode == 0, made.stderr
        checked(sim_exe, out, tmp_path / f"sim-{policy}")
        traces[policy] = rtsim.open_trace(out)
    refit, rebuild = traces["refit"], traces["rebuild"]
    assert np.array_equal(refit.rays["origin"], rebuild.rays["origin"])
    closest = refit.rays["kind"] != RAY_KINDS.index("shadow")  # shadow rays are any-hit
    assert np.array_equal(refit.hits["prim"][closest], rebuild.hits["prim"][closest])
    assert np.array_equal(refit.hits["prim"] >= 0, rebuild.hits["prim"] >= 0)
    m = json.loads((tmp_path / "refit" / "manifest.json").read_text())
    assert m["scene"]["capsules"] == 16000 and m["frames"]["count"] == 4
