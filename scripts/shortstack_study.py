#!/usr/bin/env python3
"""Short stacks with a restart trail against a full stack (docs/accel.md, "Short stacks").

For each scene and structure, one trace (diffuse rays by default) is simulated at the default
config with a stack that never overflows (`traversal.stack_entries=64`, spill: the full stack),
then with `traversal.stack_overflow=restart_trail` at several short-stack sizes, and with the
default spilling stack at the same sizes (what the short stack replaces). Per run: the extra node
steps and box tests the restarts cost (as a share of the full stack's), restarts per ray, stack
bytes moved (spills), DRAM bytes per ray and Mrays/s against the full stack. Every run must have
zero hit and work mismatches (the reference work is checked, the restarts counted apart).

Published anchors: Vaidyanathan, Woop & Benthin 2019 ("Wide BVH Traversal with a Short Stack",
HPG): on compressed wide BVHs the traversal steps with five entries are close to a full stack's;
Laine 2010 ("Restart Trail for Stackless BVH Traversal", HPG): the trail that makes restarts in a
BVH possible.

Runs are cached in OUT (a run folder with a stats.json is reused; --fresh redoes them). Writes
OUT/study.json and, with --write-docs, the table between the `short_stack_table` markers of
docs/accel.md. Usage:

    python scripts/shortstack_study.py [--out out/shortstack_study] [--resolution 160x120]
        [--scenes sponza,hairball] [--accels bvh2,bvh8,cwbvh8] [--entries 1,2,3,4,5,6,8,12]
        [--jobs 2] [--quick] [--write-docs]
"""

from __future__ import annotations

import argparse
import json
import platform
import shutil
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

from rtsim.doc_markers import write_between
from rtsim.launcher import SimJob, run_sim

REPO = Path(__file__).resolve().parents[1]
FULL_ENTRIES = 64  # never overflows: every structure's depth is within the stepper's 64 entries


def make_trace(
    scene: str, accel: str, args: argparse.Namespace, build: tuple[str, ...] = ()
) -> Path:
    """args.workload of `scene` traced with `accel` built with `build` (--build-set assignments),
    at args.resolution; cached in OUT/traces and kept while the hairball's size is the same."""
    tag = "-".join([scene, accel, *[b.replace("=", "_") for b in build]])
    folder = args.out / "traces" / f"{tag}-{args.workload}-{args.resolution}"
    params = {"hairball_triangles": getattr(args, "hairball_triangles", None)}
    stamp = folder / "study_params.json"
    cached = (folder / "trace.rtt").is_file() and stamp.is_file() and not args.fresh
    if cached and json.loads(stamp.read_text()) == params:
        return folder
    shutil.rmtree(folder, ignore_errors=True)
    cmd = [sys.executable, "-m", "rtsim", "trace", scene, "-o", str(folder), "--accel", accel]
    cmd += ["--workload", args.workload, "--resolution", args.resolution, "--threads", "0"]
    if scene == "hairball" and params["hairball_triangles"]:
        cmd += ["--hairball-triangles", str(params["hairball_triangles"])]
    for assignment in build:
        cmd += ["--build-set", assignment]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)}: exit {done.returncode}: {done.stderr[-600:]}")
    stamp.write_text(json.dumps(params))
    return folder


def simulate(trace: Path, name: str, sets: list[str], args: argparse.Namespace) -> dict[str, Any]:
    run = trace.parent.parent / "runs" / trace.name / name
    stats_file = run / "stats.json"
    if args.fresh or not stats_file.is_file():
        shutil.rmtree(run, ignore_errors=True)
        job = SimJob(trace=trace / "trace.rtt", out_dir=run, sets=sets, verdict=False)
        result = run_sim(job)
        if result.returncode != 0:
            raise SystemExit(
                f"{trace.name} {name}: rtsim-sim exit {result.returncode}: {result.stderr[-600:]}"
            )
    stats = json.loads(stats_file.read_text())
    v = stats["validation"]
    if v["hit_mismatches"] or v["work_mismatches"]:
        raise SystemExit(
            f"{trace.name} {name}: {v['hit_mismatches']} hit, "
            f"{v['work_mismatches']} work mismatches"
        )
    return dict(stats)


def points(entries: list[int]) -> list[tuple[str, list[str]]]:
    """(run name, --set assignments): the full stack, then each size short and spilling."""
    out = [("full", [f"traversal.stack_entries={FULL_ENTRIES}"])]
    for n in entries:
        out.append(
            (
                f"short{n}",
                [f"traversal.stack_entries={n}", "traversal.stack_overflow=restart_trail"],
            )
        )
        out.append((f"spill{n}", [f"traversal.stack_entries={n}"]))
    return out


def spilled_entries(stats: dict[str, Any]) -> int:
    """Stack entries written to and read back from memory, over every unit."""
    units = stats["model"].get("units", {}) or {}
    return sum(
        u.get("stack_spill_writes", 0) + u.get("stack_spill_reads", 0) for u in units.values()
    )


def row(
    scene: str, accel: str, name: str, stats: dict[str, Any], full: dict[str, Any]
) -> dict[str, Any]:
    s, f = stats["summary"], full["summary"]
    ss = stats.get("short_stack") or {}
    per_ray = ss.get("per_ray") or {}
    policy = (
        "full" if name == "full" else ("restart_trail" if name.startswith("short") else "spill")
    )
    return {
        "scene": scene,
        "accel": accel,
        "run": name,
        "policy": policy,
        "entries": FULL_ENTRIES
        if name == "full"
        else int(name.removeprefix("short").removeprefix("spill")),
        "rays": s["rays"],
        "extra_steps": ss.get("extra_steps_fraction", 0.0),
        "extra_box_tests": ss.get("extra_box_tests_fraction", 0.0),
        "restarts_per_ray": per_ray.get("restarts", 0.0),
        "spill_entries_per_ray": spilled_entries(stats) / s["rays"],
        "dram_bytes_per_ray": s["dram_bytes_per_ray"],
        "dram_vs_full": s["dram_bytes_per_ray"] / f["dram_bytes_per_ray"],
        "mrays_per_second": s["mrays_per_second"],
        "speed_vs_full": s["mrays_per_second"] / f["mrays_per_second"],
    }


def run_study(args: argparse.Namespace) -> dict[str, Any]:
    t0 = time.time()
    combos = [(sc, ac) for sc in args.scenes for ac in args.accels]
    traces = {c: make_trace(*c, args) for c in combos}
    jobs = [(c, name, sets) for c in combos for name, sets in points(args.entries)]
    by = run_points(traces, jobs, args)
    rows = [row(*c, name, by[(c, name)], by[(c, "full")]) for c, name, _ in jobs]
    return study_record(args, t0, rows)


Combo = tuple[str, str]  # (scene, structure)


def run_points(
    traces: dict[Combo, Path], jobs: list[tuple[Combo, str, list[str]]], args: argparse.Namespace
) -> dict[tuple[Combo, str], dict[str, Any]]:
    """Runs every (combo, point, settings) job on `args.jobs` threads: stats by (combo, point)."""
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        stats = list(pool.map(lambda j: simulate(traces[j[0]], j[1], j[2], args), jobs))
    return {(j[0], j[1]): st for j, st in zip(jobs, stats, strict=True)}


def study_record(args: argparse.Namespace, t0: float, rows: list[dict[str, Any]]) -> dict[str, Any]:
    """The study as saved: where and when it ran, what it traced, its wall time and its rows."""
    return {
        "host": platform.node(),
        "cpu": platform.processor() or platform.machine(),
        "date": time.strftime("%Y-%m-%d"),
        "resolution": args.resolution,
        "workload": args.workload,
        "wall_seconds": round(time.time() - t0, 1),
        "rows": rows,
    }


def pct(x: float | None) -> str:
    return "n/a" if x is None else f"{100 * x:+.1f}%"


def table(study: dict[str, Any]) -> str:
    rows = study["rows"]
    lines = [
        f"Generated by `scripts/shortstack_study.py` on {study['host']} ({study['date']}): "
        f"{study['workload']} rays at {study['resolution']}, default config (approx), one run per "
        f"point; {len(rows)} runs in {study['wall_seconds']} s, every one with zero hit and work "
        f"mismatches. Extra steps and box tests are the restarts' revisits over the full stack's "
        f"(`traversal.stack_entries={FULL_ENTRIES}`); speed and DRAM are relative to it; the spill "
        f"columns are the default spilling stack of the same size (stack entries moved per ray).",
        "",
        "| scene | structure | entries | short: extra steps | extra box tests | restarts/ray "
        "| short: speed | short: DRAM | spill: entries moved/ray | spill: speed |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    index = {(r["scene"], r["accel"], r["run"]): r for r in rows}
    for r in rows:
        if r["policy"] != "restart_trail":
            continue
        sp = index[(r["scene"], r["accel"], f"spill{r['entries']}")]
        lines.append(
            f"| {r['scene']} | {r['accel']} | {r['entries']} | {pct(r['extra_steps'])} "
            f"| {pct(r['extra_box_tests'])} | {r['restarts_per_ray']:.3f} "
            f"| {r['speed_vs_full']:.3f}x | {r['dram_vs_full']:.3f}x "
            f"| {sp['spill_entries_per_ray']:.2f} | {sp['speed_vs_full']:.3f}x |"
        )
    return "\n".join(lines) + "\n"


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument("--out", type=Path, default=Path("out/shortstack_study"))
    p.add_argument("--resolution", default="160x120")
    p.add_argument("--workload", default="diffuse")
    p.add_argument("--scenes", default="sponza,hairball")
    p.add_argument("--accels", default="bvh2,bvh8,cwbvh8")
    p.add_argument("--entries", default="1,2,3,4,5,6,8,12")
    p.add_argument("--hairball-triangles", type=int, default=50000)
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--quick", action="store_true", help="Sponza cwbvh8 at 64x48, entries 2,5,8")
    p.add_argument("--fresh", action="store_true")
    p.add_argument("--write-docs", action="store_true")
    args = p.parse_args(argv)
    if args.quick:
        args.resolution, args.scenes, args.accels, args.entries = (
            "64x48",
            "sponza",
            "cwbvh8",
            "2,5,8",
        )
    args.scenes = args.scenes.split(",")
    args.accels = args.accels.split(",")
    args.entries = [int(x) for x in args.entries.split(",")]
    return args


def save_and_print(study: dict[str, Any], text: str, args: argparse.Namespace, marker: str) -> None:
    """Writes OUT/study.json (a study whose runs all came from the cache keeps the wall time they
    took), prints the table and, with --write-docs, writes it between MARKER's markers of
    docs/accel.md. Shared with the studies that reuse this one's trace and run cache."""
    previous = args.out / "study.json"
    if previous.is_file():
        old = json.loads(previous.read_text())
        if old.get("rows") == study["rows"]:
            study["wall_seconds"] = old["wall_seconds"]
    (args.out / "study.json").write_text(json.dumps(study, indent=1))
    print(text)
    if args.write_docs:
        write_between(REPO / "docs" / "accel.md", marker, text)


def main(argv: list[str] | None = None) -> None:
    args = parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    study = run_study(args)
    save_and_print(study, table(study), args, "short_stack_table")


if __name__ == "__main__":
    main()
