"""Animated frames (docs/accel.md, "Frames"): per-frame throughput and TLAS build time.

Traces an instanced scene over N frames (`rtsim trace --frames N`: the documented motion, the
BLASes built once, a TLAS per frame), replays it on `rtsim-sim` at the default configuration
(frames in sequence, caches warm, every hit checked), and writes:

- OUT/frames_study.json: the manifest's frame block and the run's stats.json `frames`;
- the table between the frames-study markers of docs/accel.md (with --doc);
- a figure (--figure, e.g. docs/frames.png): per-frame Mrays/s and DRAM bytes per ray, and per-
  frame TLAS build time against the one-off BLAS build.

    python scripts/frames_study.py --out out/frames [--scene grove] [--frames 12] \\
        [--resolution 128x96] [--doc docs/accel.md] [--figure docs/frames.png]
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

from rtsim.doc_markers import write_between
from rtsim.launcher import SimJob, run_sim


def trace(args: argparse.Namespace) -> Path:
    folder = args.out / "trace"
    shutil.rmtree(folder, ignore_errors=True)
    cmd = [sys.executable, "-m", "rtsim", "trace", args.scene, "-o", str(folder),
           "--frames", str(args.frames), "--resolution", args.resolution]  # fmt: skip
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return folder


def simulate(folder: Path, args: argparse.Namespace) -> dict[str, Any]:
    run = args.out / "run"
    shutil.rmtree(run, ignore_errors=True)
    result = run_sim(SimJob(trace=folder, out_dir=run))
    if result.returncode != 0 or result.stats is None:
        raise SystemExit(f"rtsim-sim exit {result.returncode}: {result.stderr[-600:]}")
    return result.stats


def table(manifest: dict[str, Any], stats: dict[str, Any], args: argparse.Namespace) -> str:
    s, frames = stats["summary"], manifest["frames"]
    blas_ms, rays = frames["blas_build_ms"], s["rays"]
    mismatches = f"{s['hit_mismatches']} hit and {s['work_mismatches']} work mismatches"
    lines = [
        f"Measured by `python scripts/frames_study.py --scene {args.scene} --frames {args.frames} "
        f"--resolution {args.resolution}`: `rtsim trace` of the workload the scene calls for, "
        f"then `rtsim-sim` at the default configuration ({s['fidelity']}), the frames replayed "
        f"in one process with caches warm. TLAS build: host wall time of the tracer "
        f"({blas_ms:.0f} ms for the BLASes, once), on a 2-core machine (host times grow with "
        "load). "
        f"{rays:,} rays in all; {mismatches}.",
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


def plot(manifest: dict[str, Any], stats: dict[str, Any], path: Path, scene: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

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
    top.set_title(f"{scene}: {len(frames)} animated frames replayed with warm caches")
    handles = top.get_legend_handles_labels()[0] + twin.get_legend_handles_labels()[0]
    top.legend(handles, ["Mrays/s", "DRAM B/ray"], loc="lower center", ncol=2, framealpha=1.0)
    bottom.bar(x, [f["tlas_build_ms"] for f in frames], color="#70a050")
    blas = manifest["frames"]["blas_build_ms"]
    bottom.set_ylabel("TLAS build (ms, host)")
    bottom.set_xlabel("frame")
    bottom.set_xticks(x)
    bottom.set_title(f"TLAS rebuilt each frame; BLASes built once ({blas:.0f} ms)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, required=True)
    p.add_argument("--scene", default="grove")
    p.add_argument("--frames", type=int, default=12)
    p.add_argument("--resolution", default="128x96")
    p.add_argument("--doc", type=Path, help="write the table into this file's frames-study markers")
    p.add_argument("--figure", type=Path, help="write the figure here (PNG)")
    args = p.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    folder = trace(args)
    manifest = json.loads((folder / "manifest.json").read_text())
    stats = simulate(folder, args)
    (args.out / "frames_study.json").write_text(
        json.dumps(
            {
                "manifest_frames": manifest["frames"],
                "frames": stats["frames"],
                "summary": stats["summary"],
            },
            indent=2,
        )
    )
    text = table(manifest, stats, args)
    print(text)
    if args.doc:
        write_between(args.doc, "frames-study", text)
    if args.figure:
        plot(manifest, stats, args.figure, args.scene)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
