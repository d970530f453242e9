"""Scene names resolve the same everywhere: the command line, rtsim.load_scene, trace_scene and
write_trace all go through rtsim.scenes.resolve_scene."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import rtsim
from conftest import run_rtsim
from rtsim.errors import UnknownSceneError
from rtsim.scenes import resolve_scene


def test_load_scene_takes_a_shared_scene_name(scenes_dir: Path) -> None:
    by_name = rtsim.load_scene("LightsPunctualLamp")
    by_path = rtsim.load_scene(scenes_dir / "LightsPunctualLamp" / "LightsPunctualLamp.gltf")
    assert by_name.source == by_path.source == resolve_scene("lightspunctuallamp")
    assert by_name.triangle_count == by_path.triangle_count > 0
    assert np.array_equal(by_name.triangles(), by_path.triangles())


def test_load_scene_takes_sponza_by_name(scenes_dir: Path) -> None:
    sponza = rtsim.load_scene("sponza")
    assert Path(sponza.source) == scenes_dir / "sponza" / "Sponza.gltf"
    assert sponza.triangle_count > 200_000


def test_unknown_name_is_the_same_error_everywhere(tmp_path: Path) -> None:
    with pytest.raises(UnknownSceneError, match="unknown scene 'nosuchscene'") as err:
        rtsim.load_scene("nosuchscene")
    assert isinstance(err.value, rtsim.RtsimError) and isinstance(err.value, ValueError)
    assert "cornell" in str(err.value)  # it says what exists
    with pytest.raises(UnknownSceneError):
        rtsim.trace_scene("nosuchscene", tmp_path / "t")
    with pytest.raises(UnknownSceneError):
        rtsim.write_trace("nosuchscene", np.zeros((1, 3)), np.ones((1, 3)), out=tmp_path / "w")
    result = run_rtsim("trace", "nosuchscene", "-o", str(tmp_path / "cli"))
    assert result.returncode == 2
    assert str(err.value) in result.stderr  # the CLI prints the very same message


def test_trace_scene_takes_a_scene_name_or_object(scenes_dir: Path, tmp_path: Path) -> None:
    by_name = rtsim.trace_scene("LightsPunctualLamp", tmp_path / "a", width=16, height=12)
    scene = rtsim.load_scene("LightsPunctualLamp")
    by_object = rtsim.trace_scene(scene, tmp_path / "b", width=16, height=12)
    assert by_name["scene"]["source"] == by_object["scene"]["source"] == scene.source
    assert by_name["counts"] == by_object["counts"]
