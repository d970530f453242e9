"""The workload a scene calls for is the default (docs/architecture.md, rule 10) of `rtsim trace`,
rtsim.trace_scene and sweeps; an explicit list narrows it."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

import rtsim
from conftest import REPO, rtsim_trace
from rtsim.sweep.demo import demo_spec_text
from rtsim.sweep.runner import trace_task
from rtsim.sweep.spec import parse_spec
from rtsim.trace_file import RAY_KINDS


def kinds_in(trace: Path) -> set[str]:
    return {RAY_KINDS[k] for k in np.unique(rtsim.open_trace(trace).rays["kind"])}


def effects(manifest: dict) -> dict[str, dict]:
    return {e["name"]: e for e in manifest["workload"]["effects"]}


ALL = {"primary", "shadow", "reflection", "diffuse", "refraction"}


@pytest.mark.parametrize(
    ("scene", "called_for"),
    [
        ("LightsPunctualLamp", ALL),  # lights, metallic and transmissive materials
        ("MetalRoughSpheresNoTextures", {"primary", "reflection", "diffuse"}),  # no lights
    ],
)
def test_trace_without_workload_traces_what_the_scene_calls_for(
    scenes_dir: Path, tmp_path: Path, scene: str, called_for: set[str]
) -> None:
    out = tmp_path / "trace"
    rtsim_trace(scene, "-o", str(out), "--resolution", "24x16")
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["workload"]["requested"] == "scene"
    listed = effects(manifest)
    assert {k for k in ALL if listed[k]["simulated"]} == called_for
    for kind in ALL - called_for:
        assert not listed[kind]["why"].startswith("requested")  # nobody asked for it
    found = kinds_in(out)
    assert {"primary", "diffuse"} <= found <= called_for
    assert ("shadow" in found) == ("shadow" in called_for)
    # rtsim.trace_scene has the same default.
    api = rtsim.trace_scene(scene, tmp_path / "api", width=24, height=16)
    assert api["workload"]["effects"] == manifest["workload"]["effects"]
    assert api["counts"] == manifest["counts"]


def test_explicit_workload_narrows(scenes_dir: Path, tmp_path: Path) -> None:
    out = tmp_path / "trace"
    rtsim_trace(
        "MetalRoughSpheresNoTextures", "-o", str(out), "--resolution", "24x16",
        "--workload", "primary,shadow",
    )  # fmt: skip
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["workload"]["requested"] == ["primary", "shadow"]
    assert kinds_in(out) == {"primary"}
    listed = effects(manifest)
    assert listed["reflection"]["why"].startswith("not requested (the scene has")
    assert listed["shadow"]["why"].startswith("requested, but")


SPEC = """
scenes: [cornell]
workloads:
  - resolution: 16x12
  - name: prim
    rays: primary
    resolution: 16x12
grid:
  traversal.units: [2]
"""


def test_sweep_workload_defaults_to_the_scene(tmp_path: Path) -> None:
    spec = parse_spec(SPEC, source="spec.yaml")
    default, narrowed = spec.workloads
    assert default.rays == () and default.label == "scene"
    assert narrowed.rays == ("primary",) and narrowed.label == "prim"
    plans = spec.traces()
    assert plans[0].trace_id != plans[1].trace_id
    task = trace_task(plans[0], tmp_path)
    assert "--workload" not in task.command("OUT")
    assert task.command("OUT")[task.command("OUT").index("cornell") - 1] == "trace"
    narrowed_cmd = trace_task(plans[1], tmp_path).command("OUT")
    assert narrowed_cmd[narrowed_cmd.index("--workload") + 1] == "primary"


def test_demo_spec_does_what_the_readme_says() -> None:
    """README: the Cornell box and a 200k-triangle hairball, coherent primary rays (192x144) and
    incoherent diffuse rays (480x360), 16 configurations over four knobs."""
    spec = parse_spec(demo_spec_text(), source="demo.yaml")
    readme = (REPO / "README.md").read_text()
    assert [s.source for s in spec.scenes] == ["cornell", "hairball"]
    assert spec.scenes[1].hairball_triangles == 200_000 and "200k-triangle" in readme
    workloads = {w.label: w for w in spec.workloads}
    assert workloads["primary"].rays == ("primary",)
    assert workloads["diffuse"].rays == ("diffuse",)
    for w in spec.workloads:
        assert f"{w.width}x{w.height}" in readme
    assert len(spec.points()) == 16
    assert re.search(r"\b16 accelerator configurations\b", readme)
    assert set(spec.swept_keys) == {
        "traversal.units", "l1.size_kib", "dram.bytes_per_cycle", "treelets.enabled"
    }  # fmt: skip
