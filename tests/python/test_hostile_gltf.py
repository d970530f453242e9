"""glTF numbers read by value, every index range-checked, node transforms and special files:
the structured mutations of gltf_mutations.py, generated at test time. A valid mutation (an
integer written as a float) must load exactly as the original; every other must raise
RtsimError naming the file, the element and the key (no silent default, no wrong geometry)."""

from __future__ import annotations

import contextlib
import os
import threading
from pathlib import Path

import numpy as np
import pytest

import rtsim
from gltf_forge import triangle_doc, write_glb, write_gltf
from gltf_mutations import (
    collapse_mutations,
    number_mutations,
    rich_doc,
    type_mutations,
)
from rtsim.cli import main

NUMBER_CASES = list(number_mutations())
TYPE_CASES = list(type_mutations())


def _fingerprint(scene: rtsim.Scene) -> tuple:
    """Everything a silently dropped number would change: geometry, materials, camera, light."""
    return (
        scene.triangles().tobytes(),
        scene.triangle_materials.tobytes(),
        repr(scene.cameras),
        repr(scene.lights),
        scene.instance_count,
    )


@pytest.fixture(scope="module")
def baseline(tmp_path_factory: pytest.TempPathFactory) -> tuple:
    doc, binary = rich_doc()
    path = write_gltf(tmp_path_factory.mktemp("rich") / "rich.gltf", doc, binary)
    scene = rtsim.load_scene(str(path))
    assert scene.cameras and scene.lights and scene.instance_count == 2
    assert set(scene.triangle_materials.tolist()) == {1}  # the mirror material
    return _fingerprint(scene)


def test_corpus_is_large_and_mixed() -> None:
    assert len(NUMBER_CASES) > 150
    assert sum(m.valid for m in NUMBER_CASES) > 20


@pytest.mark.parametrize("case", NUMBER_CASES, ids=lambda m: m.name)
def test_number_mutation(case, baseline: tuple, tmp_path: Path) -> None:
    _doc, binary = rich_doc()
    paths = [write_gltf(tmp_path / "m.gltf", case.doc, binary)]
    if case.valid:
        paths.append(write_glb(tmp_path / "m.glb", case.doc, binary))  # the GLB re-container path
    for path in paths:
        if case.valid:
            assert _fingerprint(rtsim.load_scene(str(path))) == baseline, path
            continue
        with pytest.raises(rtsim.RtsimError) as info:
            rtsim.load_scene(str(path))
        message = str(info.value)
        assert str(path) in message and case.key in message, message


@pytest.mark.parametrize("case", TYPE_CASES, ids=lambda m: m.name)
def test_type_mutation(case, tmp_path: Path) -> None:
    _doc, binary = rich_doc()
    path = write_gltf(tmp_path / "t.gltf", case.doc, binary)
    with pytest.raises(rtsim.RtsimError) as info:
        rtsim.load_scene(str(path))
    assert str(path) in str(info.value) and case.key in str(info.value), str(info.value)


@pytest.mark.parametrize("case", list(collapse_mutations()), ids=lambda c: c[0])
def test_collapsed_scene_refused_with_a_camera(case, tmp_path: Path, capsys) -> None:
    name, doc, fragment = case
    _doc, binary = rich_doc()
    path = write_gltf(tmp_path / f"{name}.gltf", doc, binary)
    code = main(["trace", str(path), "-o", str(tmp_path / "out"), "--resolution", "8x8"])
    err = " ".join(capsys.readouterr().err.split())
    assert code == 2, err
    assert str(path) in err and fragment in err and "collapses" in err, err
    assert not (tmp_path / "out" / "trace.rtt").exists()


def test_hidden_instance_beside_a_visible_one_loads(tmp_path: Path) -> None:
    """One node scaled to 0 (a hidden object) does not make the scene wrong: it loads."""
    doc, binary = rich_doc()
    doc["nodes"].append({"name": "hidden", "mesh": 0, "scale": [0, 0, 0]})
    doc["scenes"][0]["nodes"].append(3)
    assert rtsim.load_scene(str(write_gltf(tmp_path / "h.gltf", doc, binary))).instance_count == 3


def _instanced(translation_type: int, normalized: bool = False) -> tuple[dict, bytes]:
    doc, binary = rich_doc()
    doc["accessors"][2].update(componentType=translation_type, normalized=normalized)
    doc["bufferViews"][2]["byteLength"] = 24
    return doc, binary


def test_instancing_translation_must_be_float(tmp_path: Path) -> None:
    path = write_gltf(tmp_path / "u8.gltf", *_instanced(5121))
    with pytest.raises(rtsim.RtsimError, match="TRANSLATION has componentType 5121") as info:
        rtsim.load_scene(str(path))
    assert "node 0 'field'" in str(info.value)


def test_nan_instance_transform_names_the_node(tmp_path: Path) -> None:
    """A non-finite translation reaches the world matrix: refused naming the node, not a
    triangle of the flattened or the instance's TLAS order."""
    doc, binary = rich_doc()
    trans = np.frombuffer(binary[64:], dtype="<f4").copy()
    trans[4] = np.nan  # instance 1's y
    binary = binary[:64] + trans.tobytes()
    path = write_gltf(tmp_path / "nan.gltf", doc, binary)
    with pytest.raises(rtsim.RtsimError) as info:
        rtsim.load_scene(str(path))
    message = str(info.value)
    assert str(path) in message and "node 0 (EXT_mesh_gpu_instancing entry 1)" in message
    assert "non-finite transform" in message


def test_singular_instance_named_by_its_node_when_traced_two_level(tmp_path: Path, capsys) -> None:
    doc, binary = rich_doc()
    doc["nodes"].append({"name": "flat", "mesh": 0, "scale": [1, 0, 1]})  # a visible plane
    doc["scenes"][0]["nodes"].append(3)
    path = write_gltf(tmp_path / "flat.gltf", doc, binary)
    assert rtsim.load_scene(str(path)).instance_count == 3  # flattened: fine
    code = main(["trace", str(path), "-o", str(tmp_path / "out"), "--resolution", "8x8"])
    err = " ".join(capsys.readouterr().err.split())
    assert code == 2 and "node 3 has a singular transform" in err and "--flatten" in err, err
    code = main(
        ["trace", str(path), "-o", str(tmp_path / "o2"), "--resolution", "8x8", "--flatten"]
    )
    assert code == 0


@pytest.mark.parametrize("uri", [".", "sub", "fifo", "/dev/zero"])
def test_buffer_uri_of_a_special_file(uri: str, tmp_path: Path) -> None:
    (tmp_path / "sub").mkdir()
    os.mkfifo(tmp_path / "fifo")
    doc, _binary = triangle_doc()
    doc["buffers"][0]["uri"] = uri
    path = write_gltf(tmp_path / "u.gltf", doc)
    with pytest.raises(rtsim.RtsimError) as info:
        rtsim.load_scene(str(path))
    assert str(path) in str(info.value) and f"uri '{uri}'" in str(info.value)


def _fifo_writer_guard(path: Path) -> threading.Thread:
    """Opens the FIFO for writing after 5 s, so a reader that blocks is released (the test
    then fails on time instead of hanging)."""

    def release() -> None:
        with contextlib.suppress(OSError):  # no reader: nothing blocked
            os.close(os.open(path, os.O_WRONLY | os.O_NONBLOCK))

    t = threading.Timer(5.0, release)
    t.daemon = True
    t.start()
    return t


@pytest.mark.parametrize("kind", ["fifo", "dev_zero"])
def test_scene_that_is_a_special_file(kind: str, tmp_path: Path, capsys) -> None:
    if kind == "fifo":
        scene = tmp_path / "scene.gltf"
        os.mkfifo(scene)
        guard = _fifo_writer_guard(scene)
    else:
        scene, guard = Path("/dev/zero"), None
    code = main(["trace", str(scene), "-o", str(tmp_path / "out"), "--resolution", "8x8"])
    err = " ".join(capsys.readouterr().err.split())
    if guard is not None:
        guard.cancel()
    assert code == 2 and f"{scene}: is not a regular file" in err, err


def test_shared_scene_folder_path_traces(scenes_dir: Path, tmp_path: Path) -> None:
    folder = scenes_dir / "SimpleInstancing"
    if not folder.is_dir():
        pytest.skip("SimpleInstancing not in the shared scenes")
    by_path = rtsim.load_scene(str(folder))
    by_name = rtsim.load_scene("SimpleInstancing")
    assert by_path.triangles().tobytes() == by_name.triangles().tobytes()


def test_scene_folder_with_two_files_names_them(tmp_path: Path) -> None:
    for name in ("a.gltf", "b.glb"):
        (tmp_path / name).write_text("{}")
    with pytest.raises(rtsim.RtsimError, match=r"found: a\.gltf, b\.glb"):
        rtsim.load_scene(str(tmp_path))
