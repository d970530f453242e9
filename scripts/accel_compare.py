#!/usr/bin/env python3
"""The acceleration-structure comparison of issue 11 (docs/accel.md, "Comparison"): every
structure asked for (any registered kind and builder: `rtsim trace --help` lists them) on each
scene and ray kind. Per structure and scene: build time (median of --repeats builds), footprint,
triangle records or references, SAH cost (BVHs). Per ray kind, from the trace's per-ray work
records: steps, box tests, triangle tests, cell steps and references fetched, mean and p99.
On the model at the default config (approx): Mrays/s, DRAM bytes per ray and hit rate, for the
trace of that workload (a diffuse trace holds its primary rays too). Every simulation must have
zero hit and work mismatches. Writes the tables into docs/accel.md between the `accel-study`
markers (--write-docs) and everything to OUT/study.json. Traces and runs are cached in OUT.

    python scripts/accel_study.py [--out out/accel_study] [--resolution 320x240]
        [--accels bvh2:binned,bvh2:sbvh,grid] [--scenes sponza,bunny,hairball,...] [--write-docs]
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np

import rtsim
from rtsim.launcher import find_sim

REPO = Path(__file__).resolve().parents[1]
BEGIN, END = "<!-- accel-study:begin -->", "<!-- accel-study:end -->"
SHARED = {"sponza": "sponza/Sponza.gltf", "bunny": "stanford_bunny/bunny.gltf"}
WORK_FIELDS = ("steps", "box_tests", "tri_tests", "cell_steps", "refs")


def scene_arg(scene: str, scenes_dir: Path) -> str:
    return str(scenes_dir / SHARED[scene]) if scene in SHARED else scene


def label(accel: str) -> str:
    return accel.replace(":", " ")


def trace(
    scene: str, accel: str, workload: str, resolution: str, out: Path, args: argparse.Namespace
) -> Path:
    kind, _, builder = accel.partition(":")
    folder = out / "traces" / f"{scene}-{kind}-{builder or 'default'}-{workload}-{resolution}"
    if (folder / "manifest.json").is_file() and not args.fresh:
        return folder
    shutil.rmtree(folder, ignore_errors=True)
    cmd = [
        sys.executable,
        "-m",
        "rtsim",
        "trace",
        scene_arg(scene, args.scenes_dir),
        "-o",
        str(folder),
    ]
    cmd += ["--workload", workload, "--resolution", resolution, "--accel", kind]
    cmd += ["--hairball-triangles", str(args.hairball_triangles)]
    if builder:
        cmd += ["--builder", builder]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return folder


def simulate(folder: Path, out: Path, fresh: bool) -> dict[str, Any]:
    run = out / "runs" / folder.name
    stats_file = run / "stats.json"
    if fresh or not stats_file.is_file():
        shutil.rmtree(run, ignore_errors=True)
        subprocess.run(
            [str(find_sim()), str(folder), "-o", str(run)], check=True, stdout=subprocess.DEVNULL
        )
    stats = json.loads(stats_file.read_text())
    s = stats["summary"]
    if s["hit_mismatches"] or s["work_mismatches"]:
        raise SystemExit(
            f"{run}: {s['hit_mismatches']} hit and {s['work_mismatches']} work mismatches"
        )
    return {
        "mrays_per_second": s["mrays_per_second"],
        "dram_bytes_per_ray": s["dram_bytes_per_ray"],
        "rays": s["rays"],
    }


def work_stats(folder: Path, ray_kind: str) -> dict[str, Any]:
    t = rtsim.open_trace(folder)
    mask = np.asarray(t.rays["kind"]) == rtsim.trace_file.RAY_KINDS.index(ray_kind)
    work, hits = np.asarray(t.work)[mask], np.asarray(t.hits)[mask]
    out: dict[str, Any] = {"rays": int(mask.sum()), "hit_rate": float((hits["prim"] >= 0).mean())}
    for f in WORK_FIELDS:
        values = work[f].astype(np.float64)
        out[f] = {"mean": float(values.mean()), "p99": float(np.percentile(values, 99))}
    return out


def structure_stats(scene: str, accel: str, out: Path, args: argparse.Namespace) -> dict[str, Any]:
    """Build figures: median build time over --repeats tiny traces, the rest from the manifest."""
    builds = []
    for i in range(args.repeats):
        folder = trace(scene, accel, "primary", "8x8", out / f"build{i}", args)
        builds.append(json.loads((folder / "manifest.json").read_text())["accel"])
    a = builds[0]
    records = a.get("references", a.get("sbvh", {}).get("references"))
    if records is None:
        records = next((r["count"] for r in a["regions"] if r["name"] == "triangles"), None)
    return {
        "build_ms": statistics.median(b["build_ms"] for b in builds),
        "footprint_bytes": a["footprint_bytes"],
        "records": records,
        "sah_cost": a.get("sah_cost"),
        "kind": a["kind"],
        "builder": a.get("builder"),
    }


def fmt(value: Any, digits: int = 1) -> str:
    if value is None:
        return "-"
    return f"{value:,.{digits}f}" if isinstance(value, float) else f"{value:,}"


def tables(results: dict[str, Any], args: argparse.Namespace) -> str:
    lines = [
        f"Measured with `python scripts/accel_study.py --resolution {args.resolution} "
        f"--accels {','.join(args.accels)} --scenes {','.join(args.scenes)}` (hairball: "
        f"{args.hairball_triangles:,} triangles); build times are medians of {args.repeats} "
        "builds on a machine shared with other jobs.",
        "",
    ]
    lines += [
        "| scene | structure | build ms | footprint MiB | triangle records / refs | SAH cost |",
        "|---|---|---:|---:|---:|---:|",
    ]
    for scene in args.scenes:
        for accel in args.accels:
            b = results[scene][accel]["build"]
            lines.append(
                f"| {scene} | {label(accel)} | {fmt(b['build_ms'], 0)} | "
                f"{b['footprint_bytes'] / 2**20:.1f} | {fmt(b['records'])} | "
                f"{fmt(b['sah_cost'], 1)} |"
            )
    lines += [
        "",
        "Per ray (mean / p99) from the reference traversal; model at the default config "
        "(approx) on the whole trace of that workload.",
        "",
    ]
    lines += [
        "| scene | rays | structure | steps | box tests | tri tests | cell steps | refs "
        "| hit rate | model Mrays/s | DRAM B/ray |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for scene in args.scenes:
        for workload in args.workloads:
            for accel in args.accels:
                r = results[scene][accel][workload]
                w = r["work"]
                cells = " | ".join(f"{w[f]['mean']:.1f} / {w[f]['p99']:.0f}" for f in WORK_FIELDS)
                m = r.get("model") or {}
                lines.append(
                    f"| {scene} | {workload} | {label(accel)} | {cells} | {w['hit_rate']:.1%} | "
                    f"{fmt(m.get('mrays_per_second'), 2)} | {fmt(m.get('dram_bytes_per_ray'), 0)} |"
                )
    return "\n".join(lines)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", type=Path, default=REPO / "out" / "accel_study")
    p.add_argument("--resolution", default="320x240")
    p.add_argument("--accels", default="bvh2:binned,bvh2:sbvh,grid", type=lambda s: s.split(","))
    p.add_argument(
        "--scenes",
        default="sponza,bunny,hairball,teapot_stadium,rotated_walls,cornell",
        type=lambda s: s.split(","),
    )
    p.add_argument("--workloads", default="primary,diffuse", type=lambda s: s.split(","))
    p.add_argument("--hairball-triangles", type=int, default=200_000)
    p.add_argument(
        "--repeats", type=int, default=3, help="builds timed per structure and scene (median)"
    )
    p.add_argument("--scenes-dir", type=Path, default=REPO.parent / "shared" / "scenes")
    p.add_argument("--no-sim", action="store_true", help="reference figures only")
    p.add_argument("--fresh", action="store_true")
    p.add_argument("--write-docs", action="store_true")
    args = p.parse_args()
    results: dict[str, Any] = {}
    for scene in args.scenes:
        for accel in args.accels:
            entry = results.setdefault(scene, {}).setdefault(accel, {})
            entry["build"] = structure_stats(scene, accel, args.out, args)
            for workload in args.workloads:
                folder = trace(scene, accel, workload, args.resolution, args.out, args)
                entry[workload] = {"work": work_stats(folder, workload)}
                if not args.no_sim:
                    entry[workload]["model"] = simulate(folder, args.out, args.fresh)
                print(
                    f"{scene} {label(accel)} {workload}: {json.dumps(entry[workload])}", flush=True
                )
    (args.out / "study.json").write_text(json.dumps(results, indent=2))
    text = tables(results, args)
    print(text)
    if args.write_docs:
        doc = REPO / "docs" / "accel.md"
        content = doc.read_text()
        start, end = content.index(BEGIN) + len(BEGIN), content.index(END)
        doc.write_text(content[:start] + "\n" + text + "\n" + content[end:])


if __name__ == "__main__":
    main()
