"""Compares the space-partitioning structures with the BVHs (docs/accel.md, "Comparison: space
partitioning against BVHs"): kd-tree, BIH, octree and grid, with and without mailboxes, against
the binary BVH from its three builders (binned SAH, SBVH, LBVH), per scene and ray kind.

- build side, from `rtsim-accel-study` (one thread, median CPU time of --repeats builds):
  build time, footprint, references per triangle, SAH cost (C_t = C_i = 1 on the cells);
- per ray kind, from each trace's work records: steps (node or cell fetches), box, plane and
  triangle tests, references fetched (mean and p99), and the rays whose hit differs from the
  binary BVH's (the same rays: the workloads trace the scene's own camera);
- on the model at the default config (approx) and again with `--set mailbox.entries=E` for the
  structures that list references: Mrays/s, DRAM bytes per ray, the triangle tests the mailbox
  skipped and its hit rate. Any hit or work mismatch stops the study;
- build plus trace per frame: each structure's build time plus the time to trace R rays at the
  model's Mrays/s (the mean over the workloads), for R from --frame-rays, and the rays per frame
  from which each structure beats the binned BVH.

Traces, runs and build figures are cached in OUT (--fresh redoes them). Writes OUT/study.json,
OUT/study.md and, with --write-docs, the tables between the `partition-study` markers of
docs/accel.md. Usage:

    python scripts/partition_study.py [--out out/partition_study] [--resolution 64x48]
        [--scenes sponza,...] [--accels bvh2,kdtree,...] [--mailbox 8] [--jobs 2]
        [--render] [--write-docs]

Needs the rtsim package, `rtsim-accel-study` (or $RTSIM_ACCEL_STUDY) and the shared scenes
($RTSIM_SCENES) for sponza and bunny.
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

import rtsim

sys.path.insert(0, str(Path(__file__).resolve().parent))
import accel_study  # one driver of rtsim-accel-study, the traces and the model runs
from accel_study import build_figures, fmt, label, run_and_write, simulate_stats, study_parser

REPO = Path(__file__).resolve().parents[1]
DEFAULT_SCENES = "teapot_stadium,rotated_walls,aligned_walls,sponza,stanford_bunny,hairball,cornell"
DEFAULT_ACCELS = "bvh2,bvh2:sbvh,bvh2:lbvh,kdtree,bih,octree,grid"
#: Structures whose leaves or cells list references (a mailbox applies).
MAILBOXED = ("kdtree", "octree", "grid")
WORK = ("steps", "box_tests", "plane_tests", "tri_tests", "refs")


def trace(scene: str, accel: str, workload: str, args: argparse.Namespace) -> Path:
    # Instanced scenes flattened: the space-partitioning structures have no two-level form.
    lights = ("--lights", args.lights) if args.lights != "none" else ()
    return accel_study.trace(scene, accel, workload, args, extra=("--flatten", *lights))


def simulate(folder: Path, tag: str, sets: list[str], args: argparse.Namespace) -> dict[str, Any]:
    stats = simulate_stats(folder, args, tag, tuple(sets))
    if stats is None:
        return {"timed_out": args.sim_timeout}
    s, m = stats["summary"], stats.get("mailbox") or {}
    return {
        "mrays_per_second": s["mrays_per_second"],
        "dram_bytes_per_ray": s["dram_bytes_per_ray"],
        "tri_tests_saved_fraction": m.get("tri_tests_saved_fraction"),
        "mailbox_hit_rate": m.get("hit_rate"),
        "mailbox_hits_per_ray": s.get("mailbox_hits_per_ray"),
    }


def work_stats(folder: Path, workload: str) -> dict[str, Any]:
    out = accel_study.work_stats(folder, workload, WORK)
    manifest = json.loads((folder / "manifest.json").read_text())["accel"]
    out["accel"] = {
        k: manifest.get(k)
        for k in ("footprint_bytes", "references_per_triangle", "sah_cost", "build_ms")
    }
    return out


def one(scene: str, accel: str, workload: str, args: argparse.Namespace) -> dict[str, Any]:
    folder = trace(scene, accel, workload, args)
    entry: dict[str, Any] = {
        "work": work_stats(folder, workload),
        "model": simulate(folder, "base", [], args),
    }
    if accel.partition(":")[0] in MAILBOXED and args.mailbox:
        entry["mailbox"] = simulate(
            folder, f"mb{args.mailbox}", [f"mailbox.entries={args.mailbox}"], args
        )
    ref = np.asarray(rtsim.open_trace(trace(scene, "bvh2", workload, args)).hits)
    hits = np.asarray(rtsim.open_trace(folder).hits)
    entry["hits_differ"] = int(
        (
            (hits["prim"] != ref["prim"]) | (hits["t"].view(np.uint32) != ref["t"].view(np.uint32))
        ).sum()
    )
    print(f"partition_study: {scene} {label(accel)} {workload} done", file=sys.stderr, flush=True)
    return entry


def study(args: argparse.Namespace) -> dict[str, Any]:
    results: dict[str, Any] = {
        "measured": {
            "host": platform.node(),
            "date": time.strftime("%Y-%m-%d"),
            "args": vars(args) | {"out": str(args.out)},
        }
    }
    for scene in args.scenes:
        results[scene] = {"build": build_figures(scene, args), "rays": {}}
        for (
            w
        ) in args.workloads:  # the bvh2 traces first: every structure's hits are compared with them
            trace(scene, "bvh2", w, args)
    jobs = [(s, a, w) for s in args.scenes for a in args.accels for w in args.workloads]
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        done = list(pool.map(lambda j: one(*j, args), jobs))
    for (scene, accel, workload), entry in zip(jobs, done, strict=True):
        results[scene]["rays"].setdefault(accel, {})[workload] = entry
    return results


def build_table(results: dict[str, Any], args: argparse.Namespace) -> list[str]:
    lines = [
        "| scene | structure | build ms | footprint MiB | vs bvh2 | refs/triangle | SAH cost |",
        "|---|---|---:|---:|---:|---:|---:|",
    ]
    for scene in args.scenes:
        st = results[scene]["build"]["structures"]
        ref = st["bvh2"]["footprint_bytes"]
        for accel in args.accels:
            s = st[accel]
            refs = results[scene]["rays"][accel][args.workloads[0]]["work"]["accel"].get(
                "references_per_triangle"
            )
            mib = s["footprint_bytes"] / 2**20
            lines.append(
                f"| {scene} | {label(accel)} | {fmt(s['build_ms_cpu'], 0)} | {mib:.2f} | "
                f"{s['footprint_bytes'] / ref:.2f} | {fmt(refs, 2)} | {fmt(s.get('sah_cost'), 1)} |"
            )
    return lines


def ray_table(results: dict[str, Any], args: argparse.Namespace) -> list[str]:
    lines = [
        "| scene | rays | structure | steps | box | plane | tri tests | refs | hits vs bvh2 "
        f"| Mrays/s | DRAM B/ray | mailbox {args.mailbox}: tri tests saved | Mrays/s "
        "| DRAM B/ray |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for scene in args.scenes:
        for workload in args.workloads:
            for accel in args.accels:
                r = results[scene]["rays"][accel][workload]
                w, m, mb = r["work"], r["model"], r.get("mailbox") or {}
                cells = " | ".join(f"{w[f]['mean']:.1f} / {w[f]['p99']:.0f}" for f in WORK)
                saved = mb.get("tri_tests_saved_fraction")
                saved_text = "-" if saved is None else f"{saved:.1%}"
                lines.append(
                    f"| {scene} | {workload} | {label(accel)} | {cells} | {r['hits_differ']} | "
                    f"{fmt(m.get('mrays_per_second'), 1)} | {fmt(m.get('dram_bytes_per_ray'), 0)} "
                    f"| {saved_text} | {fmt(mb.get('mrays_per_second'), 1)} | "
                    f"{fmt(mb.get('dram_bytes_per_ray'), 0)} |"
                )
    return lines


def frame_table(results: dict[str, Any], args: argparse.Namespace) -> list[str]:
    """Build plus trace per frame: build ms + R / (Mrays/s) ms, and where each beats binned bvh2."""
    heads = " | ".join(f"{r / 1e6:g} M rays" for r in args.frame_rays)
    lines = [
        f"| scene | structure | build ms | Mrays/s | {heads} | beats bvh2 from |",
        "|---|---|---:|---:|" + "---:|" * len(args.frame_rays) + "---|",
    ]
    for scene in args.scenes:
        base = None
        for accel in args.accels:
            build = results[scene]["build"]["structures"][accel]["build_ms_cpu"]
            rates = [
                results[scene]["rays"][accel][w]["model"].get("mrays_per_second")
                for w in args.workloads
            ]
            rate = float(np.mean([x for x in rates if isinstance(x, (int, float))] or [np.nan]))
            if accel == "bvh2":
                base = (build, rate)
            total = [build + r / (rate * 1e3) for r in args.frame_rays]
            wins = "-"
            if base and accel != "bvh2":
                b_build, b_rate = base
                per_ray_gain = 1.0 / (b_rate * 1e3) - 1.0 / (rate * 1e3)  # ms saved per ray
                if build <= b_build and per_ray_gain >= 0:
                    wins = "always"
                elif per_ray_gain > 0:
                    wins = f"{(build - b_build) / per_ray_gain / 1e6:.2g} M rays"
                elif build < b_build:
                    wins = f"up to {(b_build - build) / -per_ray_gain / 1e6:.2g} M rays"
                else:
                    wins = "never"
            lines.append(
                f"| {scene} | {label(accel)} | {build:,.0f} | {rate:.1f} | "
                + " | ".join(f"{t:,.0f}" for t in total)
                + f" | {wins} |"
            )
    return lines


def tables(results: dict[str, Any], args: argparse.Namespace) -> str:
    m = results["measured"]
    tris = ", ".join(f"{s} {results[s]['build']['triangles']:,}" for s in args.scenes)
    command = (
        f"python scripts/partition_study.py --resolution {args.resolution} --repeats "
        f"{args.repeats} --mailbox {args.mailbox} --scenes {','.join(args.scenes)} "
        f"--accels {','.join(args.accels)} --workloads {','.join(args.workloads)}"
        + (f" --lights {args.lights}" if args.lights != "none" else "")
        + (f" --doc-marker {args.doc_marker}" if args.doc_marker != "partition-study" else "")
    )
    return "\n".join(
        [
            f"Measured on {m['host']} on {m['date']} with `{command}` (triangles: {tris}). "
            "Build: one thread, median CPU time of the builds, on a machine shared with other "
            "jobs; footprint: every region (nodes, references, triangle records); refs/triangle: "
            "references listed per scene triangle (leaf or cell lists; a BVH's triangle records "
            "per triangle); SAH cost with C_t = C_i = 1 over each structure's cells or boxes (the "
            "grid has none).",
            "",
            *build_table(results, args),
            "",
            "Per ray of each kind (mean / p99) from the reference traversal; *hits vs bvh2*: rays "
            "whose hit (primitive and bits of t) differs from the binary BVH's; model at the "
            "default config (approx) on the whole trace, then with "
            f"`mailbox.entries={args.mailbox}` (kd-tree, octree, grid): the share of triangle "
            "tests it skipped and the model's figures with it. Every simulation replayed its "
            "trace with 0 hit and 0 work mismatches (the script stops otherwise).",
            "",
            *ray_table(results, args),
            "",
            "Build plus trace per frame (ms): build time (host CPU, above) plus R rays at the "
            "model's mean Mrays/s over the workloads; *beats bvh2 from*: the rays per frame from "
            "which the structure's total is below the binned BVH's (its faster tracing pays back "
            "a slower build, or its faster build outweighs slower tracing up to that many rays).",
            "",
            *frame_table(results, args),
        ]
    )


def main() -> int:
    p = study_parser(__doc__, "partition_study", DEFAULT_SCENES, DEFAULT_ACCELS, "64x48")
    p.add_argument(
        "--mailbox", type=int, default=8, help="mailbox entries of the second run (0: none)"
    )
    p.add_argument(
        "--frame-rays", default="1e6,8e6", type=lambda s: [float(x) for x in s.split(",")]
    )
    p.add_argument("--sim-timeout", type=float, default=1800.0, help="seconds per simulation")
    p.add_argument(
        "--lights",
        choices=("none", "sun"),
        default="none",
        help="lights added to scenes without any (rtsim trace --lights), so shadow rays exist",
    )
    p.add_argument(
        "--doc-marker",
        default="partition-study",
        help="the docs/accel.md markers the tables go between (another comparison's section)",
    )
    args = p.parse_args()
    if "bvh2" not in args.accels:
        args.accels.insert(0, "bvh2")  # the reference every structure is compared with
    run_and_write(args, study, tables, args.doc_marker)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
