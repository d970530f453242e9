"""Animated frames (docs/accel.md, "Frames"): per-frame throughput and TLAS build time.

One instanced scene traced over N frames (`frames` in the workload: `rtsim trace --frames N`,
the documented motion, the BLASes built once, a TLAS per frame) and replayed at the default
configuration (frames in sequence, caches warm, every hit checked). Table between the
`frames-study` markers of docs/accel.md; figure docs/frames.png (per-frame Mrays/s and DRAM
bytes per ray, per-frame TLAS build time against the one-off BLAS build)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from rtsim.study import Figure, Study, StudyRun, Table
from rtsim.study.tables import pyplot


def specs(o: dict[str, Any]) -> list[dict[str, Any]]:
    """One run: the workload the scene calls for (no `rays`), over `frames` frames."""
    workload = {"name": "frames", "resolution": o["resolution"], "frames": o["frames"]}
    return [{"name": "frames", "scenes": [{"name": o["scene"]}], "workloads": [workload]}]


def _one(run: StudyRun) -> tuple[dict[str, Any], dict[str, Any]]:
    """The run's manifest `frames` block (BLAS build time, the tracer's) and its stats.json."""
    row = run.rows()[0]
    manifest = json.loads((Path(row["trace_dir"]) / "manifest.json").read_text())
    return manifest["frames"], run.stats(row)


def table(run: StudyRun) -> str:
    frames, stats = _one(run)
    s = stats["summary"]
    mismatches = f"{s['hit_mismatches']} hit and {s['work_mismatches']} work mismatches"
    lines = [
        f"Measured by `{run.command}`: `rtsim trace` of the workload the scene calls for, "
        f"then `rtsim-sim` at the default configuration ({s['fidelity']}), the frames replayed "
        f"in one process with caches warm. TLAS build: host wall time of the tracer "
        f"({frames['blas_build_ms']:.0f} ms for the BLASes, once), on a 2-core machine (host "
        f"times grow with load). {s['rays']:,} rays in all; {mismatches}.",
        "",
        "| frame | rays | TLAS nodes | TLAS build ms | cycles | Mrays/s | DRAM B/ray "
        "| L1 hit | L2 hit |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for f in stats["frames"]:
        lines.append(
            f"| {f['frame']} | {f['rays']:,} | {f['tlas_nodes']} | {f['tlas_build_ms']:.2f} | "
            f"{f['cycles']:,} | {f['mrays_per_second']:.1f} | {f['dram_bytes_per_ray']:.0f} | "
            f"{f['l1_hit_rate']:.3f} | {f['l2_hit_rate']:.3f} |"
        )
    return "\n".join(lines) + "\n"


def plot(run: StudyRun, path: Path) -> None:
    block, stats = _one(run)
    plt = pyplot()
    frames = stats["frames"]
    x = [f["frame"] for f in frames]
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7.5, 6.0), sharex=True)
    top.bar(x, [f["mrays_per_second"] for f in frames], color="#4878a8", label="Mrays/s")
    top.set_ylabel("Mrays/s (simulated)")
    twin = top.twinx()
    twin.plot(
        x, [f["dram_bytes_per_ray"] for f in frames], "o-", color="#c0504d", label="DRAM B/ray"
    )
    twin.set_ylabel("DRAM bytes per ray", color="#c0504d")
    twin.set_ylim(bottom=0)
    scene = run.options["scene"]
    top.set_title(f"{scene}: {len(frames)} animated frames replayed with warm caches")
    handles = top.get_legend_handles_labels()[0] + twin.get_legend_handles_labels()[0]
    top.legend(handles, ["Mrays/s", "DRAM B/ray"], loc="lower center", ncol=2, framealpha=1.0)
    bottom.bar(x, [f["tlas_build_ms"] for f in frames], color="#70a050")
    bottom.set_ylabel("TLAS build (ms, host)")
    bottom.set_xlabel("frame")
    bottom.set_xticks(x)
    blas = block["blas_build_ms"]
    bottom.set_title(f"TLAS rebuilt each frame; BLASes built once ({blas:.0f} ms)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


STUDY = Study(
    name="frames",
    about="animated frames: per-frame throughput with warm caches and TLAS build time",
    specs=specs,
    tables=[Table("accel.md", "frames-study", table)],
    figures=[Figure("frames.png", plot)],
    # The documented run (docs/accel.md): the forest's 5,185 instances over 12 frames.
    options={"scene": "forest", "frames": 12, "resolution": "96x72"},
    quick={"scene": "grove", "frames": 3, "resolution": "16x12"},  # grove: 36 instances
)
