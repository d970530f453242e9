"""The analytic level on animated traces (docs/fidelity.md, "Frames at the analytic level"): the
moving procedural scenes and the grove traced over several frames, each replayed at analytic,
approx and detailed at the default configuration (the build unit on), with each level's cycles
against detailed's, the build unit's cycles against detailed's and each run's wall time (its
`summary.wall_seconds`; the analytic level's with its per-trace analysis, built by its run).
Table between the `analytic-frames` markers of docs/fidelity.md."""

from __future__ import annotations

from typing import Any

from rtsim.study import Study, StudyRun, Table

LEVELS = ("analytic", "approx", "detailed")


def specs(o: dict[str, Any]) -> list[dict[str, Any]]:
    """One spec per scene: its frames under its policy, the three levels as points."""
    out = []
    for scene, frames, policy in zip(o["scenes"], o["frames"], o["policies"], strict=True):
        workload = {"name": policy, "resolution": o["resolution"], "frames": frames,
                    "frame_policy": policy}  # fmt: skip
        points = [{"label": lv, "set": {"fidelity": lv}} for lv in LEVELS]
        out.append({"name": f"analytic-frames-{scene}", "scenes": [{"name": scene}],
                    "workloads": [workload], "points": points})  # fmt: skip
    return out


def table(run: StudyRun) -> str:
    o = run.options
    lines = [
        f"Measured by `{run.command}` ({o['resolution']}, default config: 8 units x 16 contexts, "
        "the build unit on; rtsim-sim git "
        f"{run.measured().get('git', '?')}; wall: each run's `summary.wall_seconds` on the 2-core "
        "machine, two runs at a time, the analytic level's with its analysis). Error = the level's "
        "cycles against `detailed`'s; builds = the build unit's cycles over the frames.",
        "",
        "| trace | level | cycles | error | build cycles | build error | wall (s) |",
        "|---|---|---:|---:|---:|---:|---:|",
    ]
    for scene, frames, policy in zip(o["scenes"], o["frames"], o["policies"], strict=True):
        rows = {lv: run.row(scene=scene, point=lv) for lv in LEVELS}
        stats = {lv: run.stats(r) for lv, r in rows.items()}
        det = stats["detailed"]
        det_build = sum(f["build_cycles"] for f in det["frames"])
        for lv in LEVELS:
            s = stats[lv]["summary"]
            build = sum(f["build_cycles"] for f in stats[lv]["frames"])
            err = s["cycles"] / det["summary"]["cycles"] - 1
            build_err = build / det_build - 1 if det_build else 0.0
            wall = s["wall_seconds"]  # the simulator's own, without the process or the verdict
            label = f"{scene} ({frames} frames, {policy}; {det['summary']['rays']:,} rays)"
            lines.append(
                f"| {label if lv == LEVELS[0] else ''} | {lv} | {s['cycles']:,} | {err:+.1%} | "
                f"{build:,} | {build_err:+.1%} | {wall:.2f} |"
            )
    return "\n".join(lines) + "\n"


STUDY = Study(
    name="analytic_frames",
    about="the analytic level on animated traces: cycles and builds against detailed, wall time",
    specs=specs,
    tables=[Table("fidelity.md", "analytic-frames", table)],
    options={
        # a refitted cloth, a refitted exploding hairball (its tree loosens over the frames), a
        # rebuilt skinned tube, the grove's moving instances (TLAS only)
        "scenes": ["cloth", "exploding_hairball", "skinned_tube", "grove"],
        "frames": [8, 8, 8, 4],
        "policies": ["refit", "refit", "rebuild", "rebuild"],
        "resolution": "64x48",
    },
    quick={
        "scenes": ["exploding_hairball"],
        "frames": [3],
        "policies": ["refit"],
        "resolution": "24x18",
    },
)
