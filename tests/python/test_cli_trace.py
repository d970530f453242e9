"""`rtsim trace` end to end through the command line, and the trace folder it writes."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

import rtsim
from conftest import TRACE_HEIGHT, TRACE_WIDTH, run_rtsim
from rtsim.heatmaps import pixel_work


def test_trace_folder_contents(cornell_trace: Path) -> None:
    for name in (
        "trace.rtt",
        "manifest.json",
        "render.png",
        "heatmap_nodes.png",
        "heatmap_tris.png",
    ):
        path = cornell_trace / name
        assert path.is_file() and path.stat().st_size > 0, name
    for name in ("render.png", "heatmap_nodes.png", "heatmap_tris.png"):
        assert (cornell_trace / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    manifest = json.loads((cornell_trace / "manifest.json").read_text())
    assert isinstance(manifest, dict) and manifest


def test_open_trace(cornell_trace: Path) -> None:
    trace = rtsim.open_trace(cornell_trace)
    assert trace.path == cornell_trace / "trace.rtt"
    assert isinstance(trace.rays, np.memmap)
    assert isinstance(trace.hits, np.memmap) and isinstance(trace.work, np.memmap)
    n = len(trace.rays)
    assert n == len(trace.hits) == len(trace.work) > 0
    assert trace.rays.dtype.names == (
        "origin",
        "tmin",
        "direction",
        "tmax",
        "pixel",
        "kind",
        "flags",
        "depth",
    )
    primary = trace.rays["kind"] == 0
    assert primary.sum() > 0 and (trace.rays["depth"][primary] == 0).all()
    assert (trace.rays["pixel"] < TRACE_WIDTH * TRACE_HEIGHT).all()
    assert len(np.unique(trace.rays["kind"])) > 1  # secondary rays were traced
    assert (trace.work["steps"] > 0).any()
    assert trace.nodes is not None and len(trace.nodes) > 0
    assert trace.triangles is not None
    assert trace.scene_name == "cornell"
    trace.verify()
    # Same file through the .rtt path.
    assert len(rtsim.open_trace(cornell_trace / "trace.rtt").rays) == n


def test_trace_hits_match_trace_rays(cornell_trace: Path, cornell: rtsim.Scene) -> None:
    """The reference hits in the trace are what trace_rays returns for the same rays."""
    trace = rtsim.open_trace(cornell_trace)
    rays = np.asarray(trace.rays[:5000])
    ref = np.asarray(trace.hits[:5000])
    closest = (rays["flags"] & 1) == 0
    hits = rtsim.trace_rays(
        cornell,
        rays["origin"][closest],
        rays["direction"][closest],
        rays["tmin"][closest],
        rays["tmax"][closest],
    )
    assert (hits["prim"] == ref["prim"][closest]).all()
    assert (hits["t"].view(np.uint32) == ref["t"][closest].view(np.uint32)).all()
    occluded = rtsim.trace_rays(
        cornell,
        rays["origin"][~closest],
        rays["direction"][~closest],
        rays["tmin"][~closest],
        rays["tmax"][~closest],
        any_hit=True,
    )
    assert ((occluded["prim"] >= 0) == (ref["prim"][~closest] >= 0)).all()


def test_heatmap_sums(cornell_trace: Path) -> None:
    trace = rtsim.open_trace(cornell_trace)
    nodes, tris = pixel_work(trace, TRACE_WIDTH, TRACE_HEIGHT, ("steps", "tri_tests"))
    primary = trace.rays["kind"] == 0
    assert nodes.primary.shape == (TRACE_HEIGHT, TRACE_WIDTH)
    assert nodes.primary.sum() == trace.work["steps"][primary].sum()
    assert nodes.all_rays.sum() == trace.work["steps"].astype(np.int64).sum()
    assert tris.all_rays.sum() >= tris.primary.sum() > 0


def test_truncated_trace_names_the_file(cornell_trace: Path, tmp_path: Path) -> None:
    bad = tmp_path / "truncated.rtt"
    data = (cornell_trace / "trace.rtt").read_bytes()
    bad.write_bytes(data[: len(data) // 2])
    with pytest.raises(rtsim.RtsimError, match=r"truncated\.rtt"):
        rtsim.open_trace(bad)


def test_wrong_magic_is_refused(cornell_trace: Path, tmp_path: Path) -> None:
    bad = tmp_path / "magic.rtt"
    data = bytearray((cornell_trace / "trace.rtt").read_bytes())
    data[0:8] = b"NOTATRCE"
    bad.write_bytes(bytes(data))
    with pytest.raises(rtsim.RtsimError, match=r"magic\.rtt"):
        rtsim.open_trace(bad)


def test_corrupted_payload_fails_verification(cornell_trace: Path, tmp_path: Path) -> None:
    folder = tmp_path / "corrupt"
    shutil.copytree(cornell_trace, folder)
    trace = rtsim.open_trace(folder)
    offset = trace.sections["rays"].offset + 7
    data = bytearray((folder / "trace.rtt").read_bytes())
    data[offset] ^= 0xFF
    (folder / "trace.rtt").write_bytes(bytes(data))
    with pytest.raises(rtsim.RtsimError, match=r"trace\.rtt"):
        rtsim.open_trace(folder).verify()


def test_missing_trace_is_a_clear_error(tmp_path: Path) -> None:
    with pytest.raises(rtsim.RtsimError, match="no trace file"):
        rtsim.open_trace(tmp_path)


def test_malformed_gltf_exits_2(tmp_path: Path) -> None:
    bad = tmp_path / "mangled.gltf"
    bad.write_text(
        '{"asset": {"version": "2.0"}, "buffers": [{"byteLength": 12, "uri": "missing.bin"}]'
    )
    result = run_rtsim("trace", str(bad), "-o", str(tmp_path / "out"))
    assert result.returncode == 2
    assert "rtsim: error:" in result.stderr and "mangled.gltf" in result.stderr
    assert "Traceback" not in result.stderr


def test_bad_arguments_exit_2(tmp_path: Path) -> None:
    for args in (
        ["--resolution", "0x10"],
        ["--workload", "primary,sparkles"],
        ["--camera", "1,2,3"],
    ):
        result = run_rtsim("trace", "cornell", "-o", str(tmp_path / "o"), *args)
        assert result.returncode == 2, args
        assert "error" in result.stderr


def test_scenes_and_scene_commands(tmp_path: Path) -> None:
    listed = run_rtsim("scenes")
    assert listed.returncode == 0 and "cornell" in listed.stdout
    written = run_rtsim("scene", "cornell", "-o", str(tmp_path))
    assert written.returncode == 0, written.stderr
    assert (tmp_path / "cornell.gltf").is_file()
    unknown = run_rtsim("scene", "nonesuch", "-o", str(tmp_path))
    assert unknown.returncode == 2 and "nonesuch" in unknown.stderr
