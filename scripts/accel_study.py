"""Compares acceleration structures per scene and ray kind (docs/accel.md, "Comparison").

Any registered kind and builder (`rtsim trace --help` lists them), written KIND or KIND:BUILDER:

- build side, from `rtsim-accel-study` (one thread, median of --repeats builds): build time,
  footprint, structure bytes (every region but the triangle records), node bytes, SAH cost, and
  for the wide kinds the SAH cost of the greedy collapse of the same binary tree;
- per ray kind, from the trace's per-ray work records (one trace per workload, `primary` and
  `diffuse`; the diffuse trace holds the diffuse bounces only): steps (node or cell fetches), box
  tests, triangle tests (mean and p99), hit rate, and the rays whose hit (primitive and bits of
  t) differs from the binary BVH's trace of the same workload;
- on the model at the default config (`rtsim-sim`, approx) on the whole trace of the workload:
  Mrays/s, DRAM bytes per ray, L1 and L2 hit rates; any hit or work mismatch stops the study;
- derived: the extra work of each compressed kind over its fp32 twin (same tree: quantisation's
  alone) and of the octant order over front-to-back.

Traces, runs and build figures are cached in OUT (--fresh redoes them). Writes OUT/study.json,
OUT/study.md and, with --write-docs, the tables between the `accel-study` markers of
docs/accel.md. Usage:

    python scripts/accel_study.py [--out out/accel_study] [--resolution 128x96]
        [--accels bvh2,bvh2:sbvh,bvh4,...,grid] [--scenes sponza,bunny,...] [--jobs 2]
        [--no-sim] [--render] [--write-docs]

Needs the rtsim package, `rtsim-accel-study` (installed next to `rtsim-bench`, or
$RTSIM_ACCEL_STUDY) and the shared scenes ($RTSIM_SCENES) for sponza and bunny.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

import rtsim
from rtsim.doc_markers import write_between
from rtsim.launcher import SimJob, run_sim
from rtsim.scenes import resolve_scene

REPO = Path(__file__).resolve().parents[1]
DEFAULT_SCENES = "sponza,bunny,hairball,teapot_stadium,rotated_walls,cornell"
DEFAULT_ACCELS = "bvh2,bvh2:sbvh,bvh4,bvh6,bvh8,cwbvh6,cwbvh8,bvh8_octant,cwbvh8_octant,grid"
WORK = ("steps", "box_tests", "tri_tests")
#: Same tree, one difference: quantisation (cw vs fp32) or the child order (octant vs distance).
TWINS = {"cwbvh6": "bvh6", "cwbvh8": "bvh8", "bvh8_octant": "bvh8", "cwbvh8_octant": "cwbvh8"}


def find_study() -> Path:
    env = os.environ.get("RTSIM_ACCEL_STUDY")
    if env:
        return Path(env)
    installed = Path(rtsim.__file__).resolve().parent / "bin" / "rtsim-accel-study"
    if installed.is_file():
        return installed
    found = shutil.which("rtsim-accel-study")
    if not found:
        sys.exit("accel_study: rtsim-accel-study not found (build it, or set RTSIM_ACCEL_STUDY)")
    return Path(found)


def run(cmd: list[str]) -> None:
    result = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if result.returncode not in (0,):
        sys.exit(f"accel_study: {' '.join(cmd)} failed ({result.returncode}):\n{result.stderr}")


def label(accel: str) -> str:
    return accel.replace(":", " ")


def build_figures(scene: str, args: argparse.Namespace) -> dict[str, Any]:
    """rtsim-accel-study on one scene for every structure (cached in OUT/build)."""
    path = args.out / "build" / f"{scene}.json"
    if args.fresh or not path.is_file():
        path.parent.mkdir(parents=True, exist_ok=True)
        cmd = [str(find_study()), resolve_scene(scene), "--accel", ",".join(args.accels)]
        cmd += ["--repeat", str(args.repeats), "--json", str(path)]
        cmd += ["--hairball-triangles", str(args.hairball_triangles)]
        run(cmd)
    return dict(json.loads(path.read_text()))


def trace(
    scene: str, accel: str, workload: str, args: argparse.Namespace, extra: tuple[str, ...] = ()
) -> Path:
    """One workload of a scene traced with one structure (`kind` or `kind:builder`; cached in
    OUT/traces); `extra` are more `rtsim trace` arguments."""
    kind, _, builder = accel.partition(":")
    name = f"{scene}-{kind}-{builder or 'default'}-{workload}-{args.resolution}"
    name += "".join(e.replace("--", "-") for e in extra)  # another trace with other arguments
    folder = args.out / "traces" / name
    if (folder / "manifest.json").is_file() and not args.fresh:
        return folder
    shutil.rmtree(folder, ignore_errors=True)
    cmd = [sys.executable, "-m", "rtsim", "trace", resolve_scene(scene), "-o", str(folder)]
    cmd += ["--workload", workload, "--resolution", args.resolution, "--accel", kind]
    cmd += ["--hairball-triangles", str(args.hairball_triangles), *extra]
    cmd += ["--builder", builder] if builder else []
    run(cmd)
    return folder


def simulate_stats(
    folder: Path, args: argparse.Namespace, tag: str = "", sets: tuple[str, ...] = ()
) -> dict[str, Any] | None:
    """stats.json of the trace run on the model with `sets` (cached in OUT/runs/NAME[-TAG]);
    None when it ran over --sim-timeout. Any hit or work mismatch stops the study."""
    out = args.out / "runs" / (f"{folder.name}-{tag}" if tag else folder.name)
    stats_file = out / "stats.json"
    if args.fresh or not stats_file.is_file():
        shutil.rmtree(out, ignore_errors=True)
        try:
            job = SimJob(trace=folder, out_dir=out, sets=list(sets), verdict=False)
            result = run_sim(job, timeout=args.sim_timeout)
        except OSError as err:
            sys.exit(f"{Path(sys.argv[0]).stem}: cannot run rtsim-sim: {err}")
        if result.timed_out:
            print(f"{out.name}: no model figures (over {args.sim_timeout} s)", file=sys.stderr)
            return None
    if not stats_file.is_file():
        sys.exit(f"{Path(sys.argv[0]).stem}: rtsim-sim wrote no {stats_file}")
    stats = dict(json.loads(stats_file.read_text()))
    s = stats["summary"]
    if s["hit_mismatches"] or s["work_mismatches"]:
        sys.exit(f"{out}: {s['hit_mismatches']} hit and {s['work_mismatches']} work mismatches")
    return stats


def simulate(folder: Path, args: argparse.Namespace) -> dict[str, Any]:
    stats = simulate_stats(folder, args)
    if stats is None:
        return {"timed_out": args.sim_timeout}
    keys = ("mrays_per_second", "dram_bytes_per_ray", "l1_hit_rate", "l2_hit_rate", "rays")
    return {k: stats["summary"].get(k) for k in keys}


def work_stats(folder: Path, ray_kind: str, fields: tuple[str, ...] = WORK) -> dict[str, Any]:
    """Mean, p99 and sum of each work count over the trace's rays of one kind, and hit rate."""
    t = rtsim.open_trace(folder)
    mask = np.asarray(t.rays["kind"]) == rtsim.trace_file.RAY_KINDS.index(ray_kind)
    work, hits = np.asarray(t.work)[mask], np.asarray(t.hits)[mask]
    out: dict[str, Any] = {"rays": int(mask.sum()), "hit_rate": float((hits["prim"] >= 0).mean())}
    for f in fields:
        v = work[f].astype(np.float64)
        out[f] = {
            "mean": float(v.mean()),
            "p99": float(np.percentile(v, 99)),
            "sum": float(v.sum()),
        }
    return out


def one(scene: str, accel: str, workload: str, args: argparse.Namespace) -> dict[str, Any]:
    folder = trace(scene, accel, workload, args)
    entry: dict[str, Any] = {"work": work_stats(folder, workload)}
    if not args.no_sim:
        entry["model"] = simulate(folder, args)
    print(f"accel_study: {scene} {label(accel)} {workload} done", file=sys.stderr, flush=True)
    return entry


def study(args: argparse.Namespace) -> dict[str, Any]:
    results: dict[str, Any] = {}
    for scene in args.scenes:
        results[scene] = {"build": build_figures(scene, args), "rays": {}}
    jobs = [(s, a, w) for s in args.scenes for a in args.accels for w in args.workloads]
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        done = list(pool.map(lambda j: one(*j, args), jobs))
    for (scene, accel, workload), entry in zip(jobs, done, strict=True):
        results[scene]["rays"].setdefault(accel, {})[workload] = entry
    return results


def hit_differences(results: dict[str, Any], args: argparse.Namespace) -> None:
    """Per structure and workload: rays whose hit differs from bvh2's (same rays, same order)."""
    for scene in args.scenes:
        rays = results[scene]["rays"]
        if "bvh2" not in rays:
            continue
        for workload in args.workloads:
            ref = np.asarray(rtsim.open_trace(trace(scene, "bvh2", workload, args)).hits)
            for accel in args.accels:
                hits = np.asarray(rtsim.open_trace(trace(scene, accel, workload, args)).hits)
                differ = (hits["prim"] != ref["prim"]) | (
                    hits["t"].view(np.uint32) != ref["t"].view(np.uint32)
                )
                rays[accel][workload]["hits_differ"] = int(differ.sum())


def extra_work(rays: dict[str, Any], workload: str) -> dict[str, dict[str, float]]:
    """Per derived kind: percent more steps/box/triangle tests than its twin."""
    out = {}
    for kind, twin in TWINS.items():
        if kind in rays and twin in rays:
            ours, theirs = rays[kind][workload]["work"], rays[twin][workload]["work"]
            out[kind] = {
                f: 100.0 * (ours[f]["sum"] / theirs[f]["sum"] - 1.0) if theirs[f]["sum"] else 0.0
                for f in WORK
            }
    return out


def fmt(x: Any, digits: int = 1) -> str:
    if x is None:
        return "-"
    if isinstance(x, str):
        return x
    return f"{x:,.{digits}f}" if isinstance(x, float) else f"{x:,}"


def build_table(results: dict[str, Any], args: argparse.Namespace) -> list[str]:
    lines = [
        "| scene | structure | build ms | footprint MiB | vs bvh2 | structure MiB | vs bvh2 "
        "| node B | SAH cost | SAH greedy |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for scene in args.scenes:
        st = results[scene]["build"]["structures"]
        ref = st.get("bvh2", {})
        for accel in args.accels:
            s = st[accel]

            def ratio(key: str, s: dict[str, Any] = s, ref: dict[str, Any] = ref) -> str:
                return f"{s[key] / ref[key]:.2f}" if ref.get(key) else "-"

            lines.append(
                f"| {scene} | {label(accel)} | {fmt(s['build_ms_cpu'], 0)} | "
                f"{s['footprint_bytes'] / 2**20:.2f} | {ratio('footprint_bytes')} | "
                f"{s['structure_bytes'] / 2**20:.2f} | {ratio('structure_bytes')} | "
                f"{fmt(s.get('node_bytes', s.get('cell_bytes')))} | {fmt(s.get('sah_cost'), 1)} | "
                f"{fmt(s.get('sah_cost_greedy'), 1)} |"
            )
    return lines


def ray_table(results: dict[str, Any], args: argparse.Namespace) -> list[str]:
    lines = [
        "| scene | rays | structure | steps | box tests | tri tests | hit rate | hits vs bvh2 "
        "| model Mrays/s | DRAM B/ray | L1 hit | L2 hit |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for scene in args.scenes:
        for workload in args.workloads:
            for accel in args.accels:
                r = results[scene]["rays"][accel][workload]
                w, m = r["work"], r.get("model") or {}
                cells = " | ".join(f"{w[f]['mean']:.1f} / {w[f]['p99']:.0f}" for f in WORK)
                if m.get("timed_out"):  # the model ran out of time: say so, not a blank
                    m = {"mrays_per_second": f"> {m['timed_out']:g} s"}
                lines.append(
                    f"| {scene} | {workload} | {label(accel)} | {cells} | {w['hit_rate']:.1%} | "
                    f"{fmt(r.get('hits_differ'))} | "
                    f"{fmt(m.get('mrays_per_second'), 2)} | {fmt(m.get('dram_bytes_per_ray'), 0)} "
                    f"| {fmt(m.get('l1_hit_rate'), 3)} | {fmt(m.get('l2_hit_rate'), 3)} |"
                )
    return lines


def extra_table(results: dict[str, Any], args: argparse.Namespace) -> list[str]:
    lines = [
        "| scene | rays | structure | vs | steps | box tests | tri tests |",
        "|---|---|---|---|---:|---:|---:|",
    ]
    for scene in args.scenes:
        for workload in args.workloads:
            for kind, e in extra_work(results[scene]["rays"], workload).items():
                cells = " | ".join(f"{e[f]:+.1f}%" for f in WORK)
                lines.append(f"| {scene} | {workload} | {kind} | {TWINS[kind]} | {cells} |")
    return lines if len(lines) > 2 else []


def tables(results: dict[str, Any], args: argparse.Namespace) -> str:
    tris = {s: results[s]["build"]["triangles"] for s in args.scenes}
    lines = [
        f"Measured with `python scripts/accel_study.py --resolution {args.resolution} "
        f"--repeats {args.repeats} --scenes {','.join(args.scenes)} --accels "
        f"{','.join(args.accels)}` (triangles: "
        + ", ".join(f"{s} {n:,}" for s, n in tris.items())
        + "). Build: one thread, median CPU time of the builds, on a machine shared with "
        "other jobs; structure = every region but the triangle records (nodes; for the grid, "
        "cells and references); node B = the record a step fetches (the grid: a cell).",
        "",
        *build_table(results, args),
        "",
        "Per ray of each kind (mean / p99) from the reference traversal (for the grid a step is "
        "a cell step and every reference fetched is a triangle test); model at the default "
        "config (approx) on the trace of that workload; *hits vs bvh2* counts the rays whose "
        "hit (primitive and bits of t) differs from the binary BVH's"
        + (
            f"; '> {args.sim_timeout:g} s': the simulation was stopped after that long "
            "(--sim-timeout) and has no model figures."
            if args.sim_timeout
            else "."
        ),
        "",
        *ray_table(results, args),
    ]
    extra = extra_table(results, args)
    if extra:
        lines += ["", "Extra work of quantisation and of the octant order, over the twin:", ""]
        lines += extra
    return "\n".join(lines)


def study_parser(
    doc: str, out: str, scenes: str, accels: str, resolution: str
) -> argparse.ArgumentParser:
    """The options the structure studies share (this one and partition_study.py)."""
    p = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    p.add_argument("--out", type=Path, default=REPO / "out" / out)
    p.add_argument("--scenes", default=scenes, type=lambda s: s.split(","))
    p.add_argument("--accels", default=accels, type=lambda s: s.split(","))
    p.add_argument("--workloads", default="primary,diffuse", type=lambda s: s.split(","))
    p.add_argument("--resolution", default=resolution)
    p.add_argument("--repeats", type=int, default=3, help="builds timed per structure (median)")
    p.add_argument("--hairball-triangles", type=int, default=200_000)
    p.add_argument("--jobs", type=int, default=2, help="traces and simulations at once")
    p.add_argument("--fresh", action="store_true", help="redo cached builds, traces and runs")
    p.add_argument("--render", action="store_true", help="only rewrite tables from OUT/study.json")
    p.add_argument("--write-docs", action="store_true", help="write the tables into docs/accel.md")
    return p


def run_and_write(
    args: argparse.Namespace,
    study: Callable[[argparse.Namespace], dict[str, Any]],
    tables: Callable[[dict[str, Any], argparse.Namespace], str],
    marker: str,
) -> None:
    """Runs the study (or reads OUT/study.json with --render) and writes OUT/study.json,
    OUT/study.md and, with --write-docs, the tables between docs/accel.md's `marker` markers."""
    args.out.mkdir(parents=True, exist_ok=True)
    if args.render:
        results = json.loads((args.out / "study.json").read_text())
    else:
        results = study(args)
        (args.out / "study.json").write_text(json.dumps(results, indent=2, default=str) + "\n")
    text = tables(results, args)
    (args.out / "study.md").write_text(text + "\n")
    print(text)
    if args.write_docs:
        write_between(REPO / "docs" / "accel.md", marker, text)


def main() -> int:
    p = study_parser(__doc__, "accel_study", DEFAULT_SCENES, DEFAULT_ACCELS, "128x96")
    p.add_argument("--no-sim", action="store_true", help="reference figures only")
    p.add_argument(
        "--sim-timeout", type=float, default=None, help="seconds per simulation (then no figures)"
    )
    args = p.parse_args()

    def with_hit_differences(a: argparse.Namespace) -> dict[str, Any]:
        results = study(a)
        hit_differences(results, a)
        return results

    run_and_write(args, with_hit_differences, tables, "accel-study")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
