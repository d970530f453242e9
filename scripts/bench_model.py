#!/usr/bin/env python3
"""Benchmark of the SystemC model: simulated rays per wall-second on Sponza diffuse
rays with the default config, the ratio of simulation wall time to the reference tracer's time
for the same rays (both single-threaded, same run), linearity of wall time in the ray count, and
peak memory as the trace grows 10x. Not a test: it prints figures for docs/benchmarks.md.

    python scripts/bench_model.py [--scene sponza] [--base 256x192] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import rtsim
from rtsim.launcher import SimJob, run_sim
from rtsim.scenes import resolve_scene


def make_trace(scene: str, out: Path, width: int, height: int) -> None:
    cmd = [
        sys.executable,
        "-m",
        "rtsim",
        "trace",
        scene,
        "-o",
        str(out),
        "--workload",
        "diffuse",
        "--resolution",
        f"{width}x{height}",
        "--threads",
        "0",
    ]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def reference_seconds(scene_path: str, trace_dir: Path) -> tuple[float, int]:
    """Wall time of the reference tracer (rtsim.trace_rays: one thread) on the trace's rays."""
    scene = rtsim.load_scene(scene_path)
    rays = rtsim.open_trace(trace_dir).rays
    origins = np.ascontiguousarray(rays["origin"])
    directions = np.ascontiguousarray(rays["direction"])
    tmin, tmax = np.ascontiguousarray(rays["tmin"]), np.ascontiguousarray(rays["tmax"])
    scene.triangles()  # load outside the timing
    rtsim.trace_rays(scene, origins[:16], directions[:16], tmin[:16], tmax[:16])  # builds the BVH
    start = time.perf_counter()
    hits = rtsim.trace_rays(scene, origins, directions, tmin, tmax)
    elapsed = time.perf_counter() - start
    expected = rtsim.open_trace(trace_dir).hits
    assert np.array_equal(hits["prim"], expected["prim"]), (
        "reference re-trace differs from the trace"
    )
    return elapsed, len(rays)


def simulate(trace_dir: Path, run_dir: Path) -> dict:
    """Runs rtsim-sim once; wall time, and its peak resident memory as it reports it (the
    rusage of a forked child would include this Python process's pages from before exec)."""
    result = run_sim(SimJob(trace=trace_dir, out_dir=run_dir))
    wall = result.wall_seconds
    if result.returncode != 0 or result.stats is None:
        raise SystemExit(f"rtsim-sim failed on {trace_dir}: {result.stderr[-400:]}")
    stats = result.stats
    return {
        "wall_seconds": wall,
        "peak_rss_mib": stats["summary"]["peak_memory_mib"],
        "rays": stats["summary"]["rays"],
        "hit_mismatches": stats["summary"]["hit_mismatches"],
        "model_seconds": stats["summary"]["wall_seconds"],
        "mrays_per_second_at_clock": stats["summary"]["mrays_per_second"],
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="sponza")
    parser.add_argument("--base", default="256x192", help="resolution of the 1x trace")
    parser.add_argument("--scales", default="1,2,5,10", help="ray-count multiples to run")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    width, height = (int(v) for v in args.base.split("x"))
    scene_path = resolve_scene(args.scene)
    rows = []
    with tempfile.TemporaryDirectory(prefix="rtsim_bench_model_") as tmp:
        for scale in (float(s) for s in args.scales.split(",")):
            w, h = round(width * scale**0.5), round(height * scale**0.5)
            trace_dir = Path(tmp) / f"trace_{scale:g}x"
            make_trace(scene_path, trace_dir, w, h)
            ref, n = reference_seconds(scene_path, trace_dir)
            sim = simulate(trace_dir, Path(tmp) / f"run_{scale:g}x")
            row = {
                "scale": scale,
                "resolution": f"{w}x{h}",
                "rays": n,
                "reference_seconds": ref,
                **sim,
                "sim_rays_per_wall_second": n / sim["wall_seconds"],
                "sim_over_reference": sim["wall_seconds"] / ref,
            }
            rows.append(row)
            print(
                f"{scale:>4g}x {w}x{h:<5} {n:>8} rays  sim {sim['wall_seconds']:6.2f} s "
                f"({row['sim_rays_per_wall_second'] / 1e3:6.1f} k rays/s, "
                f"peak {sim['peak_rss_mib']:6.1f} MiB)  reference {ref:6.3f} s  "
                f"ratio {row['sim_over_reference']:5.1f}  mismatches {sim['hit_mismatches']}",
                flush=True,
            )
    slope = np.polyfit([r["rays"] for r in rows], [r["wall_seconds"] for r in rows], 1)
    fit = {"seconds_per_million_rays": slope[0] * 1e6, "fixed_seconds": slope[1]}
    print(
        f"linear fit: wall = {fit['fixed_seconds']:.2f} s + "
        f"{fit['seconds_per_million_rays']:.2f} s per million rays; peak memory "
        f"{rows[0]['peak_rss_mib']:.0f} -> {rows[-1]['peak_rss_mib']:.0f} MiB"
    )
    if args.json:
        args.json.write_text(json.dumps({"scene": args.scene, "rows": rows, "fit": fit}, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
