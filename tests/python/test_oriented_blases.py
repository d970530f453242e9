"""Oriented boxes (docs/accel.md, "obvh2") in two-level structures and over frames: the BLASes
of an instanced scene built as obvh2 replay with zero mismatches on the oriented-box pipeline
(MIMD units and packets),
and a deforming mesh's obvh2 BLAS refitted per frame (its rotations fitted again on the refitted
tree) gives the closest hits a rebuild gives."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

import rtsim
from conftest import checked, run_rtsim
from rtsim.tracing import RAY_KINDS


def test_instanced_scene_with_oriented_blases_replays(sim_exe: Path, tmp_path: Path) -> None:
    out = tmp_path / "grove"
    made = run_rtsim("trace", "grove", "-o", str(out), "--resolution", "24x18", "--accel", "obvh2")
    assert made.returncode == 0, made.stderr
    accel = json.loads((out / "manifest.json").read_text())["accel"]
    assert accel["kind"] == "two_level" and accel["blas_kind"] == "obvh2"
    for sets in ([], ["traversal.model=packet"]):  # packets walk the oriented BLASes too
        stats = checked(sim_exe, out, tmp_path / f"sim{len(sets)}", *sets)
        assert sum(p["tests"] for p in stats["model"]["obb"].values()) > 0


def test_refitted_oriented_blas_gives_the_rebuilt_ones_hits(tmp_path: Path) -> None:
    traces = {}
    for policy in ("refit", "rebuild"):
        out = tmp_path / policy
        made = run_rtsim("trace", "exploding_hairball", "-o", str(out), "--resolution", "24x18",
                         "--accel", "obvh2", "--frames", "3", "--frame-policy", policy)  # fmt: skip
        assert made.returncode == 0, made.stderr
        traces[policy] = rtsim.open_trace(out)
    refit, rebuild = traces["refit"], traces["rebuild"]
    closest = refit.rays["kind"] != RAY_KINDS.index("shadow")  # any-hit rays may name another
    assert np.array_equal(refit.hits["prim"][closest], rebuild.hits["prim"][closest])
    assert np.array_equal(refit.hits["prim"] >= 0, rebuild.hits["prim"] >= 0)
    frames = json.loads((tmp_path / "refit" / "manifest.json").read_text())["frames"]["per_frame"]
    assert [b["action"] for f in frames for b in f["build"]["blas"]] == ["build", "refit", "refit"]
