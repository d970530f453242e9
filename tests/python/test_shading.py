"""Shading and the frame (docs/shading.md): a trace's shading sections (materials, textures at
addresses, per-ray parents and texel addresses), the shading block's frame loops, and what it
reports: texel addresses equal the reference tracer's, every ray is traced and shaded once in
dependency order, a scene without textures builds no texture cache, hits do not change with
shading options, and the frame-time breakdown sums to the frame time.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import rtsim
from conftest import checked, run_rtsim

BREAKDOWN = ("raygen", "build", "traversal", "reorder", "shading")


@pytest.fixture(scope="module")
def traces(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The Cornell box (procedural textures) and a small hairball (none), two bounces."""
    root = tmp_path_factory.mktemp("shading")
    out = {}
    for name, extra in (("cornell", []), ("hairball", ["--hairball-triangles", "4000"])):
        out[name] = root / name
        made = run_rtsim("trace", name, "-o", str(out[name]), "--resolution", "32x24",
                         "--bounces", "2", *extra)  # fmt: skip
        assert made.returncode == 0, made.stderr
    return out


def shading_of(stats: dict) -> dict:
    return stats["model"]["shading"]


def test_manifest_and_sections(traces: dict[str, Path]) -> None:
    manifest = json.loads((traces["cornell"] / "manifest.json").read_text())
    assert manifest["trace_version"] == 6
    sh = manifest["shading"]
    origins = {t["origin"] for t in sh["textures"]}
    assert origins == {"procedural"} and all(t["mips"] == 10 for t in sh["textures"])
    hair = json.loads((traces["hairball"] / "manifest.json").read_text())["shading"]
    assert hair["textures"] == [] and "no texture model" in hair["texture_model"]
    # Every ray's parent comes before it and is a path ray of the previous depth.
    trace = rtsim.open_trace(traces["cornell"])
    shade = trace.section("SHAD")
    parent = shade["parent"]
    assert len(shade) == len(trace.rays)
    i = np.nonzero(parent >= 0)[0]
    assert (parent[i] < i).all()
    assert (trace.rays["depth"][parent[i]] + 1 == trace.rays["depth"][i]).all()
    assert (parent[trace.rays["depth"] == 0] == -1).all()


@pytest.mark.parametrize("loop", ["wavefront", "inflight"])
def test_frame_checks_and_breakdown(traces: dict[str, Path], sim_exe: Path, tmp_path: Path,
                                    loop: str) -> None:  # fmt: skip
    stats = checked(sim_exe, traces["cornell"], tmp_path / "run", "shading.enabled=true",
                    f"shading.frame_loop={loop}")  # fmt: skip
    sh = shading_of(stats)
    v = stats["validation"]
    assert v["texel_mismatches"] == 0 and v["order_violations"] == 0
    assert sh["rays"] == stats["summary"]["rays"] == v["shaded_rays"]
    assert sh["texture_samples"] > 0 and sh["tex_hit_rate"] is not None
    assert sum(sh["breakdown"][k] for k in BREAKDOWN) == sh["frame_cycles"]
    assert sh["frame_cycles"] >= stats["summary"]["cycles"]
    assert 0.0 < sh["shading_share"] < 1.0
    assert (
        stats["model"]["dram"]["by_kind"].get("texture", {}).get("reads", 0) > 0
        or stats["model"]["l2"]["by_kind"]["texture"]["reads"] > 0
    )
    if loop == "wavefront":
        # One wavefront per depth: primaries, then each bounce's path and shadow rays, then the
        # last bounce's shadow rays (depths 0..3 for two bounces).
        assert [w["rays"] for w in sh["wavefronts"]] == list(
            np.bincount(rtsim.open_trace(traces["cornell"]).rays["depth"])
        )


@pytest.mark.parametrize("model", ["mimd", "simt", "packet"])
def test_inflight_finishes_when_rays_arrive_children_first(sim_exe: Path, tmp_path: Path,
                                                           model: str) -> None:  # fmt: skip
    """At 16x12 the dealer's chunks hand a unit children before other units reach their parents
    (the trace order is not parents first across chunks): every ray must still be traced, each
    after its parent's warp, and the in-flight loop beats the wavefront loop's barriers."""
    trace = tmp_path / "cornell"
    made = run_rtsim("trace", "cornell", "-o", str(trace), "--resolution", "16x12",
                     "--bounces", "2")  # fmt: skip
    assert made.returncode == 0, made.stderr
    sets = ("shading.enabled=true", f"traversal.model={model}")
    inflight = checked(sim_exe, trace, tmp_path / "inflight", *sets, "shading.frame_loop=inflight")
    wavefront = checked(sim_exe, trace, tmp_path / "wavefront", *sets)
    v = inflight["validation"]
    assert v["order_violations"] == 0 and v["shaded_rays"] == inflight["summary"]["rays"]
    assert shading_of(inflight)["frame_cycles"] < shading_of(wavefront)["frame_cycles"]


def test_no_texture_cache_without_textures(traces: dict[str, Path], sim_exe: Path,
                                           tmp_path: Path) -> None:  # fmt: skip
    stats = checked(sim_exe, traces["hairball"], tmp_path / "run", "shading.enabled=true")
    sh = shading_of(stats)
    assert "tex_caches" not in sh and sh["tex_hit_rate"] is None and sh["texture_samples"] == 0
    built = {b["block"]: b for b in stats["instantiated"]}
    assert built["texture_cache"]["instantiated"] is False
    assert "no material samples a texture" in built["texture_cache"]["why"]
    assert "texture" not in stats["model"]["l2"].get("by_kind", {})


def test_hits_unchanged_by_shading_options(traces: dict[str, Path], sim_exe: Path,
                                           tmp_path: Path) -> None:  # fmt: skip
    base = checked(sim_exe, traces["cornell"], tmp_path / "off")
    assert "shading" not in base["model"]
    frames = {}
    for i, sets in enumerate(
        (
            ["shading.enabled=true"],
            ["shading.enabled=true", "shading.reorder=material"],
            [
                "shading.enabled=true",
                "shading.reorder=material_direction",
                "shading.frame_loop=inflight",
            ],
            ["shading.enabled=true", "shading.reorder=shader", "shading.cores=2"],
        )
    ):
        stats = checked(sim_exe, traces["cornell"], tmp_path / f"on{i}", *sets)
        assert stats["validation"]["hit_mismatches"] == 0
        assert stats["summary"]["rays"] == base["summary"]["rays"]
        frames[i] = shading_of(stats)
    # Sorting by material groups warps: no more programs per warp than completion order.
    assert frames[1]["divergence"] <= frames[0]["divergence"]
    assert frames[1]["reorder_sorted"] == frames[1]["rays"] and frames[0]["reorder_sorted"] == 0


def test_refusals_and_unused(traces: dict[str, Path], tmp_path: Path) -> None:
    result = run_rtsim("simulate", str(traces["cornell"]), "-o", str(tmp_path / "a"),
                       "--no-progress", "--set", "shading.enabled=true",
                       "--set", "fidelity=analytic")  # fmt: skip
    assert result.returncode == 2 and "a level that times the frame" in result.stderr


def test_older_trace_simulates_without_shading(traces: dict[str, Path], sim_exe: Path,
                                               tmp_path: Path) -> None:  # fmt: skip
    """A version-4 trace (no shading sections) is read as it is: shading.enabled has no effect
    and says why; a trace of a version this build does not know is refused naming both."""
    from trace_forge import as_version_5_work, read_sections, write_trace

    sections = read_sections(traces["cornell"] / "trace.rtt")
    as_version_5_work(sections)
    old = {k: v for k, v in sections.items() if k not in ("MATL", "TEXR", "PTRI", "SHAD", "TXFT")}
    folder = tmp_path / "v4"
    folder.mkdir()
    (folder / "manifest.json").write_text((traces["cornell"] / "manifest.json").read_text())

    class Old(dict):
        record_bytes = sections.record_bytes

    write_trace(folder / "trace.rtt", Old(old), version=4)
    stats = checked(sim_exe, folder, tmp_path / "run", "shading.enabled=true")
    assert "shading" not in stats["model"]
    # The textures lie above the model's own regions: the RT unit times both traces alike.
    rt_only = checked(sim_exe, traces["cornell"], tmp_path / "rt")
    for key in ("cycles", "dram_bytes", "l1_hit_rate", "l2_hit_rate"):
        assert stats["summary"][key] == rt_only["summary"][key], key
    unused = {u["key"]: u["why"] for u in stats["summary"]["resolved"]["unused"]}
    assert "no shading sections" in unused["shading.enabled"]
    write_trace(folder / "trace.rtt", Old(old), version=7)
    result = run_rtsim("simulate", str(folder), "-o", str(tmp_path / "run7"), "--no-progress")
    assert result.returncode == 2 and "trace version 7 is not supported" in result.stderr
    assert "reads versions 3 to 6" in result.stderr
