"""Flattened against two-level structures on instanced scenes (docs/accel.md, "Two-level
structures", comparison table).

For every scene, BLAS kind and mode (`--flatten`, or the default two levels):

- `rtsim trace` (the workload the scene calls for): footprint of the image, build time, peak
  memory of the tracer (`/usr/bin/time`), and per ray the node steps (TLAS and BLAS fetches of
  nodes), transforms and triangle tests;
- `rtsim-sim` at the default configuration: Mrays/s, DRAM bytes per ray, the hit and work
  mismatches (must be 0) and its peak memory.

A mode that cannot run (the forest cannot be flattened on this machine) is reported with the
first line of its error. Writes OUT/two_level_study.json and OUT/two_level_study.md. Usage:

    python scripts/two_level_study.py --out out/two_level \\
        [--scenes MetalRoughSpheresNoTextures,SimpleInstancing,grove,forest] [--accels bvh2,bvh8] \\
        [--resolution 64x48] [--repeat 3]
"""

from __future__ import annotations

import argparse
import json
import re
import statistics
import subprocess
import sys
from pathlib import Path
from typing import Any

import rtsim
from rtsim.launcher import SimJob, find_sim
from rtsim.scenes import resolve_scene


def timed(cmd: list[str]) -> tuple[subprocess.CompletedProcess[str], float]:
    """Runs cmd under /usr/bin/time -v; returns the result and its peak RSS in MiB."""
    result = subprocess.run(
        ["/usr/bin/time", "-v", *cmd], capture_output=True, text=True, check=False
    )
    match = re.search(r"Maximum resident set size \(kbytes\): (\d+)", result.stderr)
    return result, (int(match.group(1)) / 1024 if match else float("nan"))


def trace_row(scene: str, kind: str, flatten: bool, args: argparse.Namespace) -> dict[str, Any]:
    out = args.out / f"{Path(scene).stem}-{kind}-{'flat' if flatten else 'two'}"
    cmd = [sys.executable, "-m", "rtsim", "trace", scene, "-o", str(out / "trace"),
           "--accel", kind, "--resolution", args.resolution, "--bounces", "1"]  # fmt: skip
    cmd += ["--flatten"] if flatten else []
    builds, peak = [], 0.0
    for _ in range(args.repeat):
        result, rss = timed(cmd)
        if result.returncode != 0:
            lines = [s for s in result.stderr.splitlines() if "error" in s.lower()]
            return {"error": (lines or result.stderr.splitlines() or ["failed"])[-1][:200]}
        manifest = json.loads((out / "trace" / "manifest.json").read_text())
        builds.append(manifest["timing_ms"]["accel"])
        peak = max(peak, rss)
    trace = rtsim.open_trace(out / "trace")
    work, rays = trace.work, max(len(trace.rays), 1)
    row: dict[str, Any] = {
        "footprint_mib": manifest["accel"]["footprint_bytes"] / 2**20,
        "build_ms": statistics.median(builds),
        "trace_peak_mib": peak,
        "triangles": manifest["scene"]["triangles"],
        "rays": len(trace.rays),
        "steps_per_ray": float(work["steps"].sum()) / rays,
        "transforms_per_ray": float(work["transforms"].sum()) / rays,
        "tri_tests_per_ray": float(work["tri_tests"].sum()) / rays,
    }
    result, rss = timed(SimJob(trace=out / "trace", out_dir=out / "sim").command(find_sim()))
    if result.returncode != 0:
        row["sim_error"] = result.stderr.strip().splitlines()[-1][:200]
        return row
    summary = json.loads((out / "sim" / "stats.json").read_text())["summary"]
    row.update(
        mrays_per_second=summary["mrays_per_second"],
        dram_bytes_per_ray=summary["dram_bytes_per_ray"],
        mismatches=summary["hit_mismatches"] + summary["work_mismatches"],
        sim_peak_mib=rss,
    )
    return row


def short_error(text: str) -> str:
    """The part of a tracer error that says why (e.g. "flattens to N triangles (about X GiB)")."""
    match = re.search(r"flattens to (\d+) triangles \(about ([0-9.]+ GiB)", text)
    if match:
        return f"flattens to {int(match.group(1)):,} triangles, about {match.group(2)} to trace"
    return text


def markdown(rows: list[dict[str, Any]], args: argparse.Namespace) -> str:
    head = (
        f"Measured with `python scripts/two_level_study.py --scenes {args.scenes} --accels "
        f"{args.accels} --resolution {args.resolution} --repeat {args.repeat}`: build time is "
        "the median of the traces' builds, peak memory the largest resident set "
        "(`/usr/bin/time -v`); Mrays/s and DRAM bytes per ray are the model's at the default "
        "configuration. The machine was shared with other jobs.\n\n"
        "| scene | accel | mode | triangles placed | footprint MiB | build ms | trace peak MiB "
        "| steps/ray | transforms/ray | tri tests/ray | Mrays/s | DRAM B/ray | sim peak MiB "
        "| mismatches |\n|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n"
    )

    def cell(r: dict[str, Any], key: str, fmt: str) -> str:
        value = r.get(key)
        return "-" if value is None else format(value, fmt)

    lines = []
    for r in rows:
        lead = f"| {r['scene']} | {r['accel']} | {r['mode']} |"
        if "error" in r:
            lines.append(f"{lead} - | does not run: {short_error(r['error'])} |" + " |" * 9)
            continue
        lines.append(
            f"{lead} {r['triangles']:,} | {cell(r, 'footprint_mib', '.1f')} | "
            f"{cell(r, 'build_ms', ',.0f')} | {cell(r, 'trace_peak_mib', ',.0f')} | "
            f"{cell(r, 'steps_per_ray', '.1f')} | {cell(r, 'transforms_per_ray', '.2f')} | "
            f"{cell(r, 'tri_tests_per_ray', '.1f')} | {cell(r, 'mrays_per_second', '.1f')} | "
            f"{cell(r, 'dram_bytes_per_ray', '.0f')} | {cell(r, 'sim_peak_mib', ',.0f')} | "
            f"{cell(r, 'mismatches', 'd')} |"
        )
    return head + "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument(
        "--scenes", default="MetalRoughSpheresNoTextures,SimpleInstancing,grove,forest"
    )
    parser.add_argument("--accels", default="bvh2,bvh8")
    parser.add_argument("--resolution", default="64x48")
    parser.add_argument("--repeat", type=int, default=1)
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    rows = []
    for scene in args.scenes.split(","):
        path = str(resolve_scene(scene))
        for kind in args.accels.split(","):
            for flatten in (True, False):
                row = trace_row(path, kind, flatten, args)
                row.update(scene=scene, accel=kind, mode="flattened" if flatten else "two-level")
                print(json.dumps(row), flush=True)
                rows.append(row)
    (args.out / "two_level_study.json").write_text(json.dumps(rows, indent=2) + "\n")
    (args.out / "two_level_study.md").write_text(markdown(rows, args))
    print(markdown(rows, args))
    return 0


if __name__ == "__main__":
    sys.exit(main())
