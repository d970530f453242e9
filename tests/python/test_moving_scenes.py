"""Moving scenes through the whole chain (docs/accel.md, "Moving scenes"): a deforming
procedural scene traced over frames under each --frame-policy replays with every hit checked,
the build unit prices each frame's build, and the policies differ where they should (a refit
never rebuilds; a refit's build is cheaper than a rebuild's)."""

from __future__ import annotations

import itertools
import json
from pathlib import Path

import pytest

from conftest import run_rtsim, sim_stats

FRAMES, RESOLUTION = 4, "24x18"


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory, sim_exe: Path) -> dict[str, dict]:
    root = tmp_path_factory.mktemp("moving")
    out: dict[str, dict] = {}
    for policy in ("rebuild", "refit", "adaptive"):
        trace = root / policy
        result = run_rtsim("trace", "exploding_hairball", "-o", str(trace), "--resolution",
                           RESOLUTION, "--frames", str(FRAMES), "--frame-policy", policy,
                           "--workload", "primary,shadow")  # fmt: skip
        assert result.returncode == 0, result.stderr
        manifest = json.loads((trace / "manifest.json").read_text())
        stats = sim_stats(sim_exe, trace, root / f"s_{policy}")
        out[policy] = {"manifest": manifest, "stats": stats}
    return out


def test_every_policy_replays_with_every_hit_checked(runs: dict[str, dict]) -> None:
    for policy, run in runs.items():
        summary = run["stats"]["summary"]
        assert summary["hit_mismatches"] == 0 and summary["work_mismatches"] == 0, policy
        frames = run["manifest"]["frames"]
        assert frames["policy"] == policy and "deformation" in frames
        assert len(run["stats"]["frames"]) == FRAMES


def test_build_unit_prices_each_later_frame(runs: dict[str, dict]) -> None:
    for policy, run in runs.items():
        unit = run["stats"]["model"]["build_unit"]
        assert unit["frames"] == FRAMES - 1, policy
        per = run["stats"]["frames"]
        assert per[0]["build_cycles"] == 0
        assert all(f["build_cycles"] > 0 and 0 < f["build_share"] < 1 for f in per[1:]), policy
        assert unit["written_bytes"] > 0 and unit["read_bytes"] > 0
    refit = runs["refit"]["stats"]["model"]["build_unit"]
    rebuild = runs["rebuild"]["stats"]["model"]["build_unit"]
    assert refit["rebuilds"] == 0 and refit["refits"] == 2 * (FRAMES - 1)  # BLAS and TLAS
    assert rebuild["refits"] == 0
    assert refit["busy_cycles"] < rebuild["busy_cycles"]


def test_refitted_tree_loosens_over_frames(runs: dict[str, dict]) -> None:
    per = runs["refit"]["manifest"]["frames"]["per_frame"]
    ratios = [f["build"]["blas"][0]["sah_ratio"] for f in per]
    assert ratios[0] == 1.0 and all(b > a for a, b in itertools.pairwise(ratios))
    assert all(f["build"]["blas"][0]["action"] == "refit" for f in per[1:])


@pytest.mark.parametrize("policy", ["rebuild", "refit", "adaptive"])
def test_skinned_glTF_replays_under_each_policy(sim_exe: Path, tmp_path: Path,
                                                 policy: str) -> None:  # fmt: skip
    """The project's own skinned glTF (a joint chain and its animation channels, read back
    through the loader's skinning) traced over frames and replayed with every hit checked."""
    trace = tmp_path / "tube"
    result = run_rtsim("trace", "skinned_tube", "-o", str(trace), "--resolution", "16x12",
                       "--frames", "4", "--frame-policy", policy)  # fmt: skip
    assert result.returncode == 0, result.stderr
    frames = json.loads((trace / "manifest.json").read_text())["frames"]
    assert "1 skinned" in frames["deformation"] and frames["policy"] == policy
    actions = {b["action"] for f in frames["per_frame"][1:] for b in f["build"]["blas"]}
    assert actions == ({"build"} if policy == "rebuild" else {"refit"})
    stats = sim_stats(sim_exe, trace, tmp_path / "sim")
    assert stats["summary"]["hit_mismatches"] == 0 and stats["summary"]["work_mismatches"] == 0
    assert [f["build_cycles"] > 0 for f in stats["frames"]] == [False, True, True, True]
    built = {b["block"] for b in stats["instantiated"] if b["instantiated"]}
    assert "build_unit" in built
    assert stats["area"]["mm2"]["build_unit"] > 0
    assert stats["energy"]["per_ray_nj"]["build_unit"] > 0
    # The verdict weighs the build unit's knobs beside the traversal's (Amdahl over its share);
    # a run that mostly waits for its builds is bound by the build unit, and its memory stream
    # (not its datapath) is what paces these small builds.
    unit, verdict = stats["model"]["build_unit"], stats["verdict"]
    assert max(unit["compute_cycles"], unit["stream_cycles"]) <= unit["busy_cycles"]
    assert {k["part"] for k in verdict["build"]} == {"build", "traversal"}
    # Treelet scheduling holds the frame barriers: offered as an alternative too.
    assert any(k["key"] == "treelets.enabled" for k in verdict["structural"])
    # The other frame policies are structural alternatives (each a new trace).
    others = {k["to"] for k in verdict["structural"] if k["key"] == "frame_policy"}
    assert others == {"rebuild", "refit", "adaptive"} - {policy}
    assert all("--frame-policy" in k["measure"] for k in verdict["structural"]
               if k["key"] == "frame_policy")  # fmt: skip
    if unit["share"] >= 0.5:
        assert verdict["binding"] == "build" and "build unit" in verdict["text"]
        assert verdict["relax"]["key"] == "build_unit.outstanding_lines"


def test_bad_policy_and_threshold_are_refused(tmp_path: Path) -> None:
    bad = run_rtsim("trace", "cloth", "-o", str(tmp_path / "a"), "--frames", "2",
                    "--frame-policy", "sometimes")  # fmt: skip
    assert bad.returncode != 0 and "sometimes" in bad.stderr
    low = run_rtsim("trace", "cloth", "-o", str(tmp_path / "b"), "--frames", "2",
                    "--rebuild-threshold", "0.5")  # fmt: skip
    assert low.returncode != 0 and "rebuild_threshold" in low.stderr


def test_analytic_level_prices_frames_and_builds(sim_exe: Path, tmp_path: Path) -> None:
    """The analytic level on an animated trace: each frame's traversal and build, the builds
    within 2% of the detailed level's (the same build unit on a closed-form memory), the whole
    run within its 10% band on these frames (docs/fidelity.md, "Frames at the analytic level")."""
    root = tmp_path  # (48x36: the module's 24x18 frames are too few rays for a closed form)
    for policy in ("rebuild", "refit"):
        trace = root / policy
        result = run_rtsim("trace", "exploding_hairball", "-o", str(trace), "--resolution",
                           "48x36", "--frames", "3", "--frame-policy", policy)  # fmt: skip
        assert result.returncode == 0, result.stderr
        detailed = sim_stats(sim_exe, trace, root / f"d_{policy}", "fidelity=detailed")
        analytic = sim_stats(sim_exe, trace, root / f"a_{policy}", "fidelity=analytic")
        s = analytic["summary"]
        assert s["hit_mismatches"] == 0 and s["work_mismatches"] == 0 and s["frames"] == 3
        frames = analytic["frames"]
        assert [f["rays"] for f in frames] == [f["rays"] for f in detailed["frames"]]
        assert sum(f["cycles"] for f in frames) == pytest.approx(s["cycles"], abs=3)
        assert frames[0]["build_cycles"] == 0 and all(f["build_cycles"] > 0 for f in frames[1:])
        for a, d in zip(frames[1:], detailed["frames"][1:], strict=True):
            assert a["build_cycles"] == pytest.approx(d["build_cycles"], rel=0.02), policy
        # Each frame's own L1 hit rate (its analysed rays' reads): the scattering triangles lose
        # locality frame by frame, as the detailed level's do.
        rates = [f["l1_hit_rate"] for f in frames]
        assert rates[-1] < rates[0], policy
        for a, d in zip(frames, detailed["frames"], strict=True):
            assert a["l1_hit_rate"] == pytest.approx(d["l1_hit_rate"], abs=0.06), policy
        unit = analytic["model"]["build_unit"]
        assert unit["refits" if policy == "refit" else "rebuilds"] == 4
        assert s["cycles"] == pytest.approx(detailed["summary"]["cycles"], rel=0.10), policy


def test_shaded_frame_loop_builds_between_frames(runs: dict[str, dict], sim_exe: Path,
                                                 tmp_path: Path) -> None:  # fmt: skip
    """With shading, either frame loop's frames are barriers where the build unit builds the
    next frame's structures beside its camera rays' generation: each later frame carries its
    build, the frame's breakdown (with its `build` part) sums to the frame time, and the build
    unit runs the unshaded run's jobs (its busy cycles differ only by the memory it shares with a
    different traffic around it)."""
    trace = Path(runs["rebuild"]["stats"]["provenance"]["trace"])
    trace = trace.parent if trace.suffix == ".rtt" else trace
    for loop in ("wavefront", "inflight"):
        stats = sim_stats(sim_exe, trace, tmp_path / loop, "shading.enabled=true",
                          f"shading.frame_loop={loop}")  # fmt: skip
        assert stats["summary"]["hit_mismatches"] == 0 and stats["summary"]["work_mismatches"] == 0
        assert stats["validation"]["order_violations"] == 0, loop
        unused = {u["key"] for u in stats["summary"]["resolved"]["unused"]}
        assert "build_unit.enabled" not in unused
        assert [f["build_cycles"] > 0 for f in stats["frames"]] == [False] + [True] * (FRAMES - 1)
        shading = stats["model"]["shading"]
        assert sum(shading["breakdown"].values()) == shading["frame_cycles"], loop
        assert shading["breakdown"]["build"] > 0, loop
        assert sum(f["cycles"] for f in stats["frames"]) == shading["frame_cycles"], loop
        plain, unit = runs["rebuild"]["stats"]["model"]["build_unit"], stats["model"]["build_unit"]
        assert (unit["rebuilds"], unit["refits"]) == (plain["rebuilds"], plain["refits"])
        assert unit["busy_cycles"] == pytest.approx(plain["busy_cycles"], rel=0.05), loop


def test_overlapped_builds_run_beside_the_previous_frame(runs: dict[str, dict], sim_exe: Path,
                                                         tmp_path: Path) -> None:  # fmt: skip
    """build_unit.overlap (async compute into a second buffer): the next frame's structures
    are built beside the current frame's rays. The same builds run and every hit is checked; a
    frame waits only for what is left of its build, so the run is shorter than with builds at the
    barriers, or no longer than a little contention makes it (a rebuild and the rays slow each
    other's memory streams: docs/model.md, "Builds beside the traversal"), at every level and in
    both shaded frame loops; the analytic level within its measured error of `detailed`'s."""
    trace = Path(runs["rebuild"]["stats"]["provenance"]["trace"])
    trace = trace.parent if trace.suffix == ".rtt" else trace
    serial = runs["rebuild"]["stats"]
    assert all(f["build_wait_cycles"] == f["build_cycles"] for f in serial["frames"])
    overlapped: dict[str, int] = {}
    for level in ("approx", "detailed", "analytic"):
        at_barrier = serial if level == "approx" else sim_stats(
            sim_exe, trace, tmp_path / f"serial_{level}", f"fidelity={level}")  # fmt: skip
        stats = sim_stats(sim_exe, trace, tmp_path / f"overlap_{level}", f"fidelity={level}",
                          "build_unit.overlap=true")  # fmt: skip
        s = stats["summary"]
        assert s["hit_mismatches"] == 0 and s["work_mismatches"] == 0, level
        unit, plain = stats["model"]["build_unit"], at_barrier["model"]["build_unit"]
        assert (unit["rebuilds"], unit["refits"]) == (plain["rebuilds"], plain["refits"]), level
        frames = stats["frames"]
        assert all(0 <= f["build_wait_cycles"] <= f["build_cycles"] for f in frames), level
        waits = sum(f["build_wait_cycles"] for f in frames)
        assert waits < sum(f["build_cycles"] for f in frames), level
        if level != "analytic":
            assert s["cycles"] < 1.02 * at_barrier["summary"]["cycles"], level
        assert sum(f["cycles"] for f in frames) == pytest.approx(s["cycles"], abs=3), level
        overlapped[level] = s["cycles"]
    assert overlapped["analytic"] == pytest.approx(overlapped["detailed"], rel=0.25)
    for loop in ("wavefront", "inflight"):
        stats = sim_stats(sim_exe, trace, tmp_path / f"shaded_{loop}", "shading.enabled=true",
                          f"shading.frame_loop={loop}", "build_unit.overlap=true")  # fmt: skip
        assert stats["summary"]["hit_mismatches"] == 0, loop
        shading = stats["model"]["shading"]
        assert sum(shading["breakdown"].values()) == shading["frame_cycles"], loop
        assert stats["model"]["build_unit"]["rebuilds"] == serial["model"]["build_unit"]["rebuilds"]
