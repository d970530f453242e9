"""Oriented boxes (docs/accel.md, "obvh2") in two-level structures and over frames: the BLASes
of an instanced scene built as obvh2 replay with zero mismatches on the oriented-box pipeline
(MIMD units and packets),
a deforming mesh's obvh2 BLAS refitted per frame (its rotations fitted again on the refitted
tree) gives the closest hits a rebuild gives, and the build unit prices that fit."""

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


def test_build_unit_prices_an_oriented_blas_fit(sim_exe: Path, tmp_path: Path) -> None:
    """Each build and refit of an obvh2 BLAS fits every node in every table frame again: the
    build unit charges those node frames (at fit_frames_per_cycle), their energy and the fit
    datapath's area, at the timed and the analytic level alike; an axis-aligned BLAS has none."""
    stats = {}
    for accel in ("bvh2", "obvh2"):
        out = tmp_path / accel
        made = run_rtsim("trace", "exploding_hairball", "-o", str(out), "--resolution", "16x12",
                         "--accel", accel, "--frames", "3", "--frame-policy", "refit")  # fmt: skip
        assert made.returncode == 0, made.stderr
        stats[accel] = checked(sim_exe, out, tmp_path / f"sim-{accel}")
        if accel == "obvh2":
            manifest = json.loads((out / "manifest.json").read_text())
            fast = checked(sim_exe, out, tmp_path / "fast", "build_unit.fit_frames_per_cycle=4")
            analytic = checked(sim_exe, out, tmp_path / "analytic", "fidelity=analytic")
    plain, oriented = (stats[a]["model"]["build_unit"] for a in ("bvh2", "obvh2"))
    assert plain["fit_node_frames"] == 0 and "obb_fit" not in stats["bvh2"]["area"]["mm2"]
    # Every later frame's BLAS records: their nodes, each in every table frame.
    blases = manifest["accel"]["blas"]
    records = [r for f in manifest["frames"]["per_frame"][1:] for r in f["build"]["blas"]]
    assert records and all(r["action"] == "refit" for r in records)
    fits = [blases[r["blas"]] for r in records]
    frames = sum(b["nodes"] * b["obvh2"]["rotations"] for b in fits)
    assert oriented["fit_node_frames"] == frames
    assert oriented["compute_cycles"] >= frames  # one node frame a cycle
    assert fast["model"]["build_unit"]["compute_cycles"] < oriented["compute_cycles"] - frames / 2
    assert stats["obvh2"]["area"]["mm2"]["obb_fit"] > 0
    assert stats["obvh2"]["energy"]["per_ray_nj"]["obb_fit"] > 0
    assert analytic["model"]["build_unit"]["fit_node_frames"] == frames


def test_refit_that_keeps_rotations_gives_the_rebuilt_hits_for_fewer_fit_frames(
    sim_exe: Path, tmp_path: Path
) -> None:
    """With obb_refit_keeps_rotations a refit boxes each node in its kept frame only (every
    subtree in its oriented ancestors' frames): the rebuilt trees' closest hits, and far fewer
    node frames for the build unit than a refit that fits every rotation again."""
    runs = {}
    for name, sets in (("keep", ["--build-set", "obb_refit_keeps_rotations=true"]), ("fit", [])):
        out = tmp_path / name
        args = ["-o", str(out), "--resolution", "16x12", "--accel", "obvh2", "--frames", "3"]
        made = run_rtsim("trace", "exploding_hairball", *args, "--frame-policy", "refit", *sets)
        assert made.returncode == 0, made.stderr
        runs[name] = (rtsim.open_trace(out), checked(sim_exe, out, tmp_path / f"sim-{name}"))
    made = run_rtsim("trace", "exploding_hairball", "-o", str(tmp_path / "rebuild"),
                     "--resolution", "16x12", "--accel", "obvh2", "--frames", "3")  # fmt: skip
    assert made.returncode == 0, made.stderr
    rebuild = rtsim.open_trace(tmp_path / "rebuild")
    keep = runs["keep"][0]
    closest = keep.rays["kind"] != RAY_KINDS.index("shadow")
    assert np.array_equal(keep.hits["prim"][closest], rebuild.hits["prim"][closest])
    kept, fitted = (runs[n][1]["model"]["build_unit"] for n in ("keep", "fit"))
    assert 0 < kept["fit_node_frames"] < fitted["fit_node_frames"] / 10
    assert kept["busy_cycles"] < fitted["busy_cycles"] / 2
