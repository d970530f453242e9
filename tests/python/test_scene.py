"""load_scene on procedural and shared glTF scenes: counts, arrays, metadata, errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import rtsim


def test_procedural_names() -> None:
    names = rtsim.procedural_scene_names()
    assert "cornell" in names and "hairball" in names


def test_cornell_triangles(cornell: rtsim.Scene) -> None:
    tris = cornell.triangles()
    assert tris.dtype == np.float32
    assert tris.shape == (cornell.triangle_count, 3, 3)
    assert cornell.triangle_count > 10
    assert not tris.flags.writeable
    assert np.isfinite(tris).all()
    lo, hi = (np.array(b, dtype=np.float32) for b in cornell.bounds)
    flat = tris.reshape(-1, 3)
    assert (flat >= lo).all() and (flat <= hi).all()
    assert np.allclose(flat.min(axis=0), lo) and np.allclose(flat.max(axis=0), hi)


def test_cornell_metadata(cornell: rtsim.Scene) -> None:
    assert cornell.source == "cornell"
    assert cornell.instance_count >= 1
    assert not cornell.uses_instancing
    assert cornell.materials and {"name", "base_color", "metallic", "roughness"} <= set(
        cornell.materials[0]
    )
    materials = cornell.triangle_materials
    assert materials.shape == (cornell.triangle_count,)
    assert int(materials.max()) < len(cornell.materials)
    assert isinstance(cornell.lights, list) and isinstance(cornell.warnings, list)


def test_triangles_outlive_scene() -> None:
    tris = rtsim.load_scene("cornell").triangles()  # the array keeps the scene alive
    assert np.isfinite(tris).all()


def test_write_procedural_scene(tmp_path: Path) -> None:
    path = Path(rtsim.write_procedural_scene("cornell", tmp_path))
    assert path == tmp_path / "cornell.gltf" and path.is_file()
    from_file = rtsim.load_scene(path)
    assert from_file.triangle_count == rtsim.load_scene("cornell").triangle_count


def test_hairball_size_option() -> None:
    small = rtsim.load_scene("hairball", hairball_triangles=2000)
    large = rtsim.load_scene("hairball", hairball_triangles=8000)
    assert small.triangle_count < large.triangle_count


def test_unknown_scene_is_a_clear_error() -> None:
    with pytest.raises(rtsim.RtsimError, match="no_such_scene"):
        rtsim.load_scene("no_such_scene")


def test_malformed_gltf_names_the_file(tmp_path: Path) -> None:
    bad = tmp_path / "broken.gltf"
    bad.write_text('{"asset": {"version": "2.0"}, "meshes": [ oops')
    with pytest.raises(rtsim.RtsimError, match=r"broken\.gltf"):
        rtsim.load_scene(bad)


def test_shared_alpha_blend(scenes_dir: Path) -> None:
    scene = rtsim.load_scene(scenes_dir / "AlphaBlendModeTest" / "AlphaBlendModeTest.gltf")
    assert scene.triangle_count == 61
    assert scene.triangles().shape == (61, 3, 3)
    modes = {m["alpha_mode"] for m in scene.materials}
    assert {"OPAQUE", "MASK", "BLEND"} <= modes


def test_shared_instancing(scenes_dir: Path) -> None:
    scene = rtsim.load_scene(scenes_dir / "SimpleInstancing" / "SimpleInstancing.gltf")
    assert scene.triangle_count == 1500
    assert scene.instance_count == 125
    assert scene.uses_instancing
    tris = scene.triangles()
    # 125 placements of one 12-triangle cube, each somewhere else.
    centres = tris.reshape(125, 36, 3).mean(axis=1)
    gaps = np.linalg.norm(centres[:, None, :] - centres[None, :, :], axis=-1)
    assert gaps[~np.eye(125, dtype=bool)].min() > 1e-3


def test_shared_lights(scenes_dir: Path) -> None:
    scene = rtsim.load_scene(scenes_dir / "LightsPunctualLamp" / "LightsPunctualLamp.gltf")
    assert scene.triangle_count == 6000
    assert len(scene.lights) == 5
    assert all(light["type"] in ("point", "spot", "directional") for light in scene.lights)
