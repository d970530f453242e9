"""Glossy reflections (--reflections glossy) and Russian roulette (--roulette-after): recorded in
the manifest, deterministic for a seed, refused when malformed, and what they change in the rays
(docs/ray_generation.md)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import rtsim
from gltf_forge import triangle_doc, write_gltf
from rtsim.errors import RtsimError
from rtsim.kinds import RAY_KINDS
from rtsim.tracing import trace_scene


def _rays(path: Path, kind: str) -> np.ndarray:
    t = rtsim.open_trace(path)
    return np.array(t.rays[t.rays["kind"] == RAY_KINDS.index(kind)])


def _metal_floor(path: Path, roughness: float) -> Path:
    """A 20 m floor of brushed metal (the tracer frames it from above at a slant)."""
    corners = [[-10, 0, -10], [-10, 0, 10], [10, 0, 10], [-10, 0, -10], [10, 0, 10], [10, 0, -10]]
    doc, binary = triangle_doc(np.float32(corners))
    pbr = {"metallicFactor": 1.0, "roughnessFactor": roughness}
    doc["materials"] = [{"name": "brushed", "pbrMetallicRoughness": pbr}]
    doc["meshes"][0]["primitives"][0]["material"] = 0
    return write_gltf(path, doc, binary)


def test_glossy_reflections_spread_around_the_mirror_direction(tmp_path: Path) -> None:
    kw = {"width": 48, "height": 36, "workload": "primary,reflection"}
    spread = {}
    for roughness in (0.2, 0.6):
        scene = str(_metal_floor(tmp_path / f"floor{roughness}.gltf", roughness))
        mirror = trace_scene(scene, tmp_path / f"mirror{roughness}", **kw)
        glossy = trace_scene(scene, tmp_path / f"glossy{roughness}", reflections="glossy", **kw)
        assert mirror["workload"]["reflections"] == "mirror"
        assert glossy["workload"]["reflections"] == "glossy"
        a = _rays(tmp_path / f"mirror{roughness}", "reflection")
        b = _rays(tmp_path / f"glossy{roughness}", "reflection")
        assert len(a) > 200
        # The same parents: each glossy ray leaves where its pixel's mirror ray does (a few
        # below the surface are absorbed), off the mirror direction, above the floor.
        assert 0.5 * len(a) < len(b) <= len(a)
        mirror_of = {int(p): d for p, d in zip(a["pixel"], a["direction"], strict=True)}
        pairs = zip(b["pixel"], b["direction"], strict=True)
        cos = np.array([np.dot(mirror_of[int(p)], d) for p, d in pairs])
        assert np.all(b["direction"][:, 1] > 0)
        assert np.mean(cos < 1 - 1e-5) > 0.8
        spread[roughness] = float(np.mean(cos))
        again = trace_scene(scene, tmp_path / f"again{roughness}", reflections="glossy", **kw)
        assert again["workload"]["reflections"] == "glossy"
        assert np.array_equal(_rays(tmp_path / f"again{roughness}", "reflection"), b)
    assert 0.99 > spread[0.2] > spread[0.6] > 0.5  # the lobe widens with roughness


def test_roulette_ends_paths_past_its_depth(tmp_path: Path) -> None:
    kw = {"width": 32, "height": 24, "workload": "primary,diffuse", "bounces": 4}
    fixed = trace_scene("cornell", tmp_path / "fixed", **kw)
    rr = trace_scene("cornell", tmp_path / "rr", roulette_after=1, **kw)
    assert fixed["workload"]["roulette_after"] == 0 and rr["workload"]["roulette_after"] == 1
    depth_fixed = _rays(tmp_path / "fixed", "diffuse")["depth"]
    depth_rr = _rays(tmp_path / "rr", "diffuse")["depth"]
    # The first bounce is never played for; every later one loses paths (albedo < 0.95).
    assert np.sum(depth_rr == 1) == np.sum(depth_fixed == 1)
    for d in (2, 3, 4):
        assert 0 < np.sum(depth_rr == d) < np.sum(depth_fixed == d)
    assert np.sum(depth_rr == 4) < np.sum(depth_rr == 2)


def test_bad_path_options_are_refused(tmp_path: Path) -> None:
    with pytest.raises(RtsimError, match="reflections"):
        trace_scene("cornell", tmp_path / "a", width=8, height=8, reflections="shiny")
    with pytest.raises(RtsimError, match="roulette_after"):
        trace_scene("cornell", tmp_path / "b", width=8, height=8, roulette_after=-1)
    args = ["trace", "cornell", "-o", str(tmp_path / "c"), "--reflections", "shiny"]
    cli = subprocess.run([sys.executable, "-m", "rtsim", *args], capture_output=True, text=True)
    assert cli.returncode == 2 and "--reflections" in cli.stderr
