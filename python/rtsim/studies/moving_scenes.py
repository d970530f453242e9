"""Moving scenes (docs/accel.md, "Moving scenes: the structures each frame builds or refits"):
refit against rebuild over frames, and the frame where rebuilding pays.

Each deforming scene is traced over its frames under each `--frame-policy` (rebuild, refit,
adaptive at the tracer's default threshold) and replayed at the default configuration, the build
unit pricing each frame's build before its rays (docs/model.md, "Build unit"). The table gives
per scene and policy the total cycles, the build share and the rebuilds; the crossover is the
first frame whose refitted frame (build included) is slower than the rebuilt one. Table between
the `moving-scenes` markers of docs/accel.md; figure docs/moving_scenes.png (per-frame cycles and
the refitted tree's SAH cost ratio)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from rtsim.study import Figure, Study, StudyRun, Table
from rtsim.study.core import StudyError
from rtsim.study.tables import pyplot

POLICIES = ("rebuild", "refit", "adaptive")


def _scenes(o: dict[str, Any]) -> list[tuple[str, int]]:
    if len(o["scenes"]) != len(o["frames"]):
        raise StudyError("study moving_scenes: give one frame count per scene (scenes, frames)")
    return list(zip(o["scenes"], o["frames"], strict=True))


def specs(o: dict[str, Any]) -> list[dict[str, Any]]:
    """One spec per scene and policy (each policy is its own trace: the structures differ)."""
    out = []
    for scene, frames in _scenes(o):
        for policy in o["policies"]:
            workload = {"name": policy, "resolution": o["resolution"], "frames": frames,
                        "frame_policy": policy}  # fmt: skip
            out.append({"name": f"{scene}-{policy}", "scenes": [{"name": scene}],
                        "workloads": [workload]})  # fmt: skip
    return out


def _one(run: StudyRun, scene: str, policy: str) -> tuple[list[dict], dict[str, Any]]:
    """A run's per-frame manifest records and its stats.json."""
    row = run.row(scene=scene, workload=policy)
    manifest = json.loads((Path(row["trace_dir"]) / "manifest.json").read_text())
    return manifest["frames"]["per_frame"], run.stats(row)


def _rebuilds(per_frame: list[dict]) -> tuple[int, int]:
    """BLAS and TLAS builds after frame 0 (frame 0 always builds)."""
    blas = sum(b["action"] == "build" for f in per_frame[1:] for b in f["build"]["blas"])
    tlas = sum(f["build"]["tlas"]["action"] == "build" for f in per_frame[1:])
    return blas, tlas


def crossover(refit: dict[str, Any], rebuild: dict[str, Any]) -> int | None:
    """The first frame whose refitted frame takes more cycles (build included) than the rebuilt
    one; None if refitting never loses."""
    for a, b in zip(refit["frames"][1:], rebuild["frames"][1:], strict=True):
        if a["cycles"] > b["cycles"]:
            return int(a["frame"])
    return None


def table(run: StudyRun) -> str:
    o = run.options
    lines = [
        f"Measured by `{run.command}`: `rtsim trace SCENE --frames N --resolution "
        f"{o['resolution']} --frame-policy P`, then `rtsim-sim` at the defaults (approx, bvh2, "
        "the build unit's defaults); cycles are each frame's traversal and its build (before "
        "its rays). Crossover: the first frame whose refitted frame is slower than the rebuilt "
        "one.",
        "",
        "| scene, frames | policy | total Mcycles | build share | rebuilds (BLAS+TLAS) | "
        "last SAH ratio | hit, work mismatches |",
        "|---|---|---:|---:|---:|---:|---:|",
    ]
    notes = []
    for scene, frames in _scenes(o):
        runs = {p: _one(run, scene, p) for p in o["policies"]}
        for i, (policy, (per_frame, stats)) in enumerate(runs.items()):
            s = stats["summary"]
            build = sum(f["build_cycles"] for f in stats["frames"])
            blas, tlas = _rebuilds(per_frame)
            ratio = per_frame[-1]["build"]["blas"][0]["sah_ratio"]
            label = f"`{scene}`, {frames}" if i == 0 else ""
            lines.append(
                f"| {label} | {policy} | {s['cycles'] / 1e6:.2f} | {build / s['cycles']:.0%} | "
                f"{blas}+{tlas} | {ratio:.2f} | {s['hit_mismatches']}, {s['work_mismatches']} |"
            )
        if "refit" in runs and "rebuild" in runs:
            at = crossover(runs["refit"][1], runs["rebuild"][1])
            notes.append(
                f"`{scene}`: refitting "
                + (f"loses from frame {at} on" if at is not None else "never loses")
                + f" over {frames} frames."
            )
    return "\n".join(lines) + "\n\n" + " ".join(notes) + "\n"


def plot(run: StudyRun, path: Path) -> None:
    o = run.options
    scenes = _scenes(o)
    plt = pyplot()
    fig, axes = plt.subplots(2, len(scenes), figsize=(4.2 * len(scenes), 6.0), squeeze=False)
    colors = {"rebuild": "#4878a8", "refit": "#c0504d", "adaptive": "#70a050"}
    for col, (scene, _frames) in enumerate(scenes):
        top, bottom = axes[0][col], axes[1][col]
        for policy in o["policies"]:
            per_frame, stats = _one(run, scene, policy)
            x = [f["frame"] for f in stats["frames"]]
            top.plot(x, [f["cycles"] / 1e3 for f in stats["frames"]], "o-", ms=3,
                     color=colors.get(policy), label=policy)  # fmt: skip
            bottom.plot(x, [f["build"]["blas"][0]["sah_ratio"] for f in per_frame], "o-", ms=3,
                        color=colors.get(policy), label=policy)  # fmt: skip
        top.set_title(f"{scene}: cycles per frame (build included)", fontsize=10)
        top.set_ylabel("k cycles")
        top.set_ylim(bottom=0)
        top.legend(fontsize=8, framealpha=1.0)
        bottom.set_title("BLAS SAH cost / cost at its last rebuild", fontsize=10)
        bottom.set_xlabel("frame")
        bottom.axhline(1.25, color="#888888", lw=0.8, ls="--")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


STUDY = Study(
    name="moving_scenes",
    about="moving scenes: refit against rebuild over frames, the build share and the crossover",
    specs=specs,
    tables=[Table("accel.md", "moving-scenes", table)],
    figures=[Figure("moving_scenes.png", plot)],
    options={
        "scenes": ["exploding_hairball", "cloth", "skinned_tube", "exploding_furball"],
        "frames": [24, 12, 60, 24],
        "resolution": "96x72",
        "policies": list(POLICIES),
    },
    quick={
        "scenes": ["exploding_hairball", "skinned_tube"],
        "frames": [3, 3],
        "resolution": "16x12",
    },
)
