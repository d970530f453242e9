"""Animated frames through the whole chain (docs/accel.md, "Frames"): `rtsim trace --frames N`
on the grove writes one trace of N frames (BLAS regions once, a TLAS per frame, a FRMS table);
frame 0 is the one-frame trace; `rtsim-sim` replays the frames in sequence with every hit
checked and reports each frame's figures; what cannot be animated or replayed is refused with a
message naming the scene or the field.
"""

from __future__ import annotations

import itertools
import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

import rtsim
from conftest import run_rtsim, simulate

FRAMES, RESOLUTION, WORKLOAD = 3, "24x18", "primary,shadow,diffuse"


def trace(out: Path, *extra: str) -> subprocess.CompletedProcess[str]:
    return run_rtsim("trace", "grove", "-o", str(out), "--resolution", RESOLUTION,
                     "--workload", WORKLOAD, *extra)  # fmt: skip


@pytest.fixture(scope="module")
def traces(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """(the grove over FRAMES frames, the grove's one-frame trace)."""
    root = tmp_path_factory.mktemp("frames")
    for name, extra in (("animated", ["--frames", str(FRAMES)]), ("still", [])):
        result = trace(root / name, *extra)
        assert result.returncode == 0, result.stderr
    return root / "animated", root / "still"


def test_manifest_and_image(traces: tuple[Path, Path]) -> None:
    animated, still = traces
    manifest = json.loads((animated / "manifest.json").read_text())
    frames = manifest["frames"]
    assert frames["count"] == FRAMES and "spin" in frames["motion"]
    assert frames["blas_build_ms"] > 0
    per = frames["per_frame"]
    assert [f["frame"] for f in per] == list(range(FRAMES))
    assert all(f["tlas_build_ms"] > 0 and f["tlas_nodes"] > 0 for f in per)
    assert per[0]["first_ray"] == 0 and per[1]["first_ray"] == per[0]["rays"]
    trace = rtsim.open_trace(animated)
    assert len(trace.rays) == sum(f["rays"] for f in per)
    assert manifest["accel"]["stats"]["frames"] == FRAMES if "stats" in manifest["accel"] else True
    # Frame 0 is the one-frame trace: the same rays and the same reference hits, bit for bit.
    one = rtsim.open_trace(still)
    n = per[0]["rays"]
    assert n == len(one.rays)
    assert np.array_equal(trace.rays[:n].view(np.uint8), one.rays.view(np.uint8))
    assert np.array_equal(trace.hits[:n].view(np.uint8), one.hits.view(np.uint8))
    # Later frames differ: the trees moved.
    assert not np.array_equal(trace.hits[n : 2 * n]["t"], one.hits["t"])


@pytest.mark.parametrize("level", ["approx", "detailed", "functional"])
def test_replay_checks_every_hit_of_every_frame(
    traces: tuple[Path, Path], sim_exe: Path, tmp_path: Path, level: str
) -> None:
    animated, _ = traces
    result = simulate(sim_exe, animated, tmp_path / "run", f"fidelity={level}")
    assert result.returncode == 0, result.stderr
    stats = json.loads((tmp_path / "run" / "stats.json").read_text())
    s = stats["summary"]
    assert s["frames"] == FRAMES and s["hit_mismatches"] == 0 and s["work_mismatches"] == 0
    frames = stats["frames"]
    assert [f["frame"] for f in frames] == list(range(FRAMES))
    assert sum(f["rays"] for f in frames) == s["rays"]
    if level == "functional":
        assert all(f["cycles"] is None for f in frames)
        return
    # Every timed run has a verdict, its estimates on the first frame (said so).
    v = stats["verdict"]
    assert v is not None and len(v["top"]) == 3, v
    assert v["coverage"]["frames"] == FRAMES and "first frame" in v["estimate"]["method"]
    assert v["top"][0]["speedup"] is not None
    # Frames follow one another: each starts when the previous one's last ray finished.
    assert frames[0]["start_cycle"] == 0
    for a, b in itertools.pairwise(frames):
        assert b["start_cycle"] == a["end_cycle"] and b["end_cycle"] > a["end_cycle"]
    assert frames[-1]["end_cycle"] == s["cycles"]
    assert all(f["mrays_per_second"] > 0 and 0 < f["l1_hit_rate"] <= 1 for f in frames)
    total_dram = sum(f["dram_bytes"] for f in frames)
    assert total_dram == pytest.approx(s["dram_bytes"])
    # Warm caches: later frames move fewer DRAM bytes per ray than the cold first frame.
    assert min(f["dram_bytes_per_ray"] for f in frames[1:]) < frames[0]["dram_bytes_per_ray"]


@pytest.mark.parametrize("model", ["mimd", "simt"])
def test_treelet_scheduling_holds_the_frame_barriers(
    traces: tuple[Path, Path], sim_exe: Path, tmp_path: Path, model: str
) -> None:
    # The ray buffer admits a frame's rays only once dispatch releases them (the previous
    # frame's last ray finished), and counts each finished ray to the barrier.
    animated, _ = traces
    sets = ["treelets.enabled=true", f"traversal.model={model}", "fidelity=detailed"]
    result = simulate(sim_exe, animated, tmp_path / "run", *sets)
    assert result.returncode == 0, result.stderr
    stats = json.loads((tmp_path / "run" / "stats.json").read_text())
    s, frames = stats["summary"], stats["frames"]
    assert s["frames"] == FRAMES and s["hit_mismatches"] == 0 and s["work_mismatches"] == 0
    assert stats["model"]["ray_buffer"]["admitted"] == s["rays"]
    assert frames[0]["start_cycle"] == 0
    for a, b in itertools.pairwise(frames):
        assert b["start_cycle"] == a["end_cycle"] and b["end_cycle"] > a["end_cycle"]
    assert frames[-1]["end_cycle"] == s["cycles"]
    assert all(f["rays"] > 0 and f["mrays_per_second"] > 0 for f in frames)


def test_one_frame_trace_has_one_frame_entry(
    traces: tuple[Path, Path], sim_exe: Path, tmp_path: Path
) -> None:
    _, still = traces
    result = simulate(sim_exe, still, tmp_path / "run")
    assert result.returncode == 0, result.stderr
    stats = json.loads((tmp_path / "run" / "stats.json").read_text())
    assert stats["summary"]["frames"] == 1
    [frame] = stats["frames"]
    assert frame["cycles"] == stats["summary"]["cycles"] and frame["tlas_build_ms"] is None


@pytest.mark.parametrize(
    ("sets", "field"),
    [
        (["fidelity=analytic", "analytic.caches=functional"], "analytic.caches"),
    ],
)
def test_replay_refuses_what_does_not_hold_frames(
    traces: tuple[Path, Path], sim_exe: Path, tmp_path: Path, sets: list[str], field: str
) -> None:
    animated, _ = traces
    result = simulate(sim_exe, animated, tmp_path / "run", *sets)
    assert result.returncode == 2, result.stderr
    assert field in result.stderr and "animated trace" in result.stderr


def test_trace_refuses_frames_without_instancing_or_with_flatten(tmp_path: Path) -> None:
    result = run_rtsim("trace", "cornell", "-o", str(tmp_path / "c"), "--frames", "4",
                       "--resolution", "8x6")  # fmt: skip
    assert result.returncode != 0
    assert "--frames 4" in result.stderr and "places no geometry more than once" in result.stderr
    result = trace(tmp_path / "f", "--frames", "2", "--flatten")
    assert result.returncode != 0 and "--flatten" in result.stderr


def test_sampling_cuts_every_frame_into_clusters_behind_its_barrier(
    sim_exe: Path, tmp_path: Path
) -> None:
    out = tmp_path / "grove"
    made = run_rtsim("trace", "grove", "-o", str(out), "--resolution", "48x36",
                     "--workload", WORKLOAD, "--frames", "3")  # fmt: skip
    assert made.returncode == 0, made.stderr
    runs = {}
    for name, sets in (("exact", []), ("sampled", ["sampling.fraction=0.4"])):
        result = simulate(sim_exe, out, tmp_path / name, "fidelity=approx", *sets)
        assert result.returncode == 0, result.stderr
        runs[name] = json.loads((tmp_path / name / "stats.json").read_text())
    exact, sampled = runs["exact"], runs["sampled"]
    v = sampled["validation"]
    assert v["hit_mismatches"] == v["work_mismatches"] == 0
    assert v["rays_checked"] == sampled["sampling"]["simulated_rays"] < exact["summary"]["rays"]
    frames = sampled["frames"]
    assert [f["frame"] for f in frames] == [0, 1, 2]
    # Each frame's rays are the trace's; the sample simulated some of them; the frames' estimates
    # (barrier drains included) add up to the run's.
    assert [f["rays"] for f in frames] == [f["rays"] for f in exact["frames"]]
    assert sum(f["sampled_rays"] for f in frames) == v["rays_checked"]
    assert sum(f["cycles"] for f in frames) == pytest.approx(sampled["summary"]["cycles"], abs=3)
    assert sampled["sampling"]["barrier_cycles"] > 0
    low, high = sampled["summary"]["cycles_ci95"]
    assert low < sampled["summary"]["cycles"] < high
    assert sampled["summary"]["cycles"] == pytest.approx(exact["summary"]["cycles"], rel=0.25)


def test_shading_runs_frame_after_frame_in_both_frame_loops(
    traces: tuple[Path, Path], sim_exe: Path, tmp_path: Path
) -> None:
    animated, _ = traces

    def shaded_frames(name: str, *sets: str) -> dict:
        """A shaded run's stats: every check passed, frames in order summing to the frame loop's
        time, whose parts add up to it."""
        result = simulate(sim_exe, animated, tmp_path / name, "shading.enabled=true", *sets)
        assert result.returncode == 0, result.stderr
        stats = json.loads((tmp_path / name / "stats.json").read_text())
        v = stats["validation"]
        assert v["hit_mismatches"] == v["work_mismatches"] == v["texel_mismatches"] == 0
        assert v["order_violations"] == 0 and v["shaded_rays"] == v["rays_checked"]
        loop = stats["model"]["shading"]
        assert [f["frame"] for f in stats["frames"]] == list(range(FRAMES))
        assert sum(f["cycles"] for f in stats["frames"]) == loop["frame_cycles"]
        assert sum(loop["breakdown"].values()) == loop["frame_cycles"]
        return loop

    # Each frame's camera rays are generated after the frame before is shaded.
    shading = shaded_frames("run")
    # A wavefront never spans two frames: at least one per frame and depth.
    assert len(shading["wavefronts"]) >= FRAMES * 2
    # The in-flight loop holds the frames as barriers too: a frame ends when its last hit is
    # shaded, the next frame's camera rays are generated then; within a frame, rays go as their
    # parents' warps are shaded.
    loop = shaded_frames("inflight", "shading.frame_loop=inflight")
    assert loop["breakdown"]["raygen"] == shading["breakdown"]["raygen"]  # every frame's, once
