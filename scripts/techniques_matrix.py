#!/usr/bin/env python3
"""Every memory-traffic technique on every scene at every timed level (docs/papers.md,
"Every technique, every scene, every timed level").

The techniques set beside their papers in docs/papers.md each have a study of their own; this
script is the coverage check: each technique runs on Sponza, the hairball and the Cornell box at
the approx and the detailed level, beside the same run with the technique off, and every run must
have zero hit and work mismatches (the model's hits against the reference, bit for bit; the
reference work per ray, with each technique's extra work counted apart). Per run: rays, Mrays/s
and DRAM bytes per ray against the technique off, and the mismatch counts.

Runs are cached in OUT (a run folder with a stats.json is reused; --fresh redoes them). Writes
OUT/matrix.json and, with --write-docs, the table between the `techniques_matrix` markers of
docs/papers.md. Exits 1 if any run has a mismatch. Usage:

    python scripts/techniques_matrix.py [--out out/techniques] [--resolution 160x120]
        [--workload diffuse] [--scenes sponza,hairball,cornell] [--levels approx,detailed]
        [--jobs 2] [--write-docs]
"""

from __future__ import annotations

import argparse
import json
import platform
import shutil
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rtsim.doc_markers import write_between
from rtsim.launcher import SimJob, run_sim

REPO = Path(__file__).resolve().parents[1]


@dataclass(frozen=True)
class Technique:
    """One technique: the structure it runs on, its trace-time build settings and its model
    settings, and the model settings of the run it is compared with (the technique off)."""

    name: str
    paper: str
    accel: str
    build: tuple[str, ...] = ()
    sets: tuple[str, ...] = ()
    off_sets: tuple[str, ...] = field(default=())


TREELETS = ("treelets.enabled=true",)

TECHNIQUES = (
    Technique(
        "compressed leaves",
        "Benthin et al. 2018",
        "cwbvh8",
        build=("compressed_leaves=true",),
    ),
    Technique(
        "treelet prefetching into the L1",
        "Chou, Nowicki & Aamodt 2023",
        "bvh2",
        sets=(*TREELETS, "treelets.prefetch=true"),
        off_sets=TREELETS,
    ),
    Technique(
        "short stack, 5 entries, restart trail",
        "Laine 2010; Vaidyanathan et al. 2019",
        "cwbvh8",
        sets=("traversal.stack_entries=5", "traversal.stack_overflow=restart_trail"),
        off_sets=("traversal.stack_entries=64",),
    ),
    Technique(
        "reduced-precision box tests, 8 bits",
        "Keely 2014",
        "bvh2",
        sets=("traversal.box_precision_bits=8",),
    ),
    Technique(
        "treelet ray buffers",
        "Aila & Karras 2010",
        "bvh2",
        sets=TREELETS,
    ),
)


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


_LOCKS: dict[Path, threading.Lock] = {}
_LOCKS_GUARD = threading.Lock()


def simulate(trace: Path, name: str, level: str, sets: tuple[str, ...], fresh: bool) -> dict:
    run = trace.parent.parent / "runs" / trace.name / f"{name}-{level}"
    with _LOCKS_GUARD:  # two techniques may share a run (one's "on" is another's "off")
        lock = _LOCKS.setdefault(run, threading.Lock())
    with lock:
        return _simulate_once(trace, run, level, sets, fresh)


_DONE: set[Path] = set()


def _simulate_once(trace: Path, run: Path, level: str, sets: tuple[str, ...], fresh: bool) -> dict:
    stats_file = run / "stats.json"
    if (fresh and run not in _DONE) or not stats_file.is_file():
        shutil.rmtree(run, ignore_errors=True)
        job = SimJob(
            trace=trace / "trace.rtt",
            out_dir=run,
            sets=[f"fidelity={level}", *sets],
            verdict=False,
        )
        t0 = time.time()
        result = run_sim(job)
        if result.returncode != 0:
            raise SystemExit(
                f"{trace.name} {run.name}: rtsim-sim exit {result.returncode}: "
                f"{result.stderr[-600:]}"
            )
        (run / "wall_seconds.txt").write_text(f"{time.time() - t0:.2f}\n")
        _DONE.add(run)
    return dict(json.loads(stats_file.read_text()))


def run_slug(sets: tuple[str, ...]) -> str:
    return "off" if not sets else "_".join(s.split(".")[-1].replace("=", "") for s in sets)


def measure(t: Technique, scene: str, level: str, args: argparse.Namespace) -> dict[str, Any]:
    off_trace = make_trace(scene, t.accel, args)
    on_trace = make_trace(scene, t.accel, args, t.build) if t.build else off_trace
    off = simulate(off_trace, run_slug(t.off_sets), level, t.off_sets, args.fresh)
    on = simulate(on_trace, run_slug(t.sets) if t.sets else "off", level, t.sets, args.fresh)
    s, f = on["summary"], off["summary"]
    return {
        "technique": t.name,
        "paper": t.paper,
        "accel": t.accel,
        "scene": scene,
        "level": level,
        "rays": s["rays"],
        "mrays_per_second": s["mrays_per_second"],
        "speed_vs_off": s["mrays_per_second"] / f["mrays_per_second"],
        "dram_bytes_per_ray": s["dram_bytes_per_ray"],
        "dram_vs_off": s["dram_bytes_per_ray"] / max(f["dram_bytes_per_ray"], 1e-9),
        "hit_mismatches": on["validation"]["hit_mismatches"],
        "work_mismatches": on["validation"]["work_mismatches"],
        "off_mismatches": off["validation"]["hit_mismatches"]
        + off["validation"]["work_mismatches"],
    }


def run_matrix(args: argparse.Namespace) -> dict[str, Any]:
    t0 = time.time()
    # Traces first, one at a time (each uses every core), then the runs in parallel.
    for t in TECHNIQUES:
        for scene in args.scenes:
            make_trace(scene, t.accel, args)
            if t.build:
                make_trace(scene, t.accel, args, t.build)
    cells = [(t, sc, lv) for t in TECHNIQUES for sc in args.scenes for lv in args.levels]
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        rows = list(pool.map(lambda c: measure(*c, args), cells))
    return {
        "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
        "host": platform.node(),
        "workload": args.workload,
        "resolution": args.resolution,
        "wall_seconds": round(time.time() - t0, 1),
        "rows": rows,
    }


def table(result: dict[str, Any]) -> str:
    lines = [
        f"Generated by `python scripts/techniques_matrix.py --write-docs` on {result['date']} "
        f"({result['workload']} rays at {result['resolution']}, default config otherwise, "
        f"{len(result['rows']) * 2} runs counting each technique's run with it off, "
        f'{result["wall_seconds"]:.0f} s wall). "vs off": the same trace and level with the '
        "technique off (treelet prefetching: treelets without prefetching; short stack: a "
        "64-entry stack that never overflows; compressed leaves: the same structure's plain "
        "leaves; reduced-precision boxes: fp32 box tests).",
        "",
        "| technique | structure | scene | level | rays | Mrays/s | vs off | DRAM B/ray | vs off "
        "| hit / work mismatches |",
        "|---|---|---|---|---:|---:|---:|---:|---:|---:|",
    ]
    for r in result["rows"]:
        lines.append(
            f"| {r['technique']} ({r['paper']}) | `{r['accel']}` | {r['scene']} | {r['level']} "
            f"| {r['rays']:,} | {r['mrays_per_second']:.1f} | {r['speed_vs_off']:.2f}x "
            f"| {r['dram_bytes_per_ray']:.0f} | {r['dram_vs_off']:.2f}x "
            f"| {r['hit_mismatches']} / {r['work_mismatches']} |"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", type=Path, default=Path("out/techniques"))
    p.add_argument("--resolution", default="160x120")
    p.add_argument("--workload", default="diffuse")
    p.add_argument("--scenes", default="sponza,hairball,cornell")
    p.add_argument("--levels", default="approx,detailed")
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--fresh", action="store_true")
    p.add_argument("--write-docs", action="store_true")
    args = p.parse_args(argv)
    args.scenes = args.scenes.split(",")
    args.levels = args.levels.split(",")
    result = run_matrix(args)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "matrix.json").write_text(json.dumps(result, indent=1))
    text = table(result)
    print(text)
    if args.write_docs:
        write_between(REPO / "docs" / "papers.md", "techniques_matrix", text)
    bad = [r for r in result["rows"] if r["hit_mismatches"] or r["work_mismatches"]]
    bad += [r for r in result["rows"] if r["off_mismatches"]]
    for r in bad:
        print(f"mismatch: {r['technique']} {r['scene']} {r['level']}", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
