#!/usr/bin/env python3
"""Reduced-precision box tests against fp32 (docs/accel.md, "Reduced-precision box tests").

For each scene and structure, one trace (diffuse rays by default) is simulated at the default
config (approx) with fp32 box tests (`traversal.box_precision_bits=0`) and at several mantissa
widths, plus a pair of detailed runs (fp32 and one width) on the first scene and structure. Per
run: the extra walk's box hits, node steps, box and triangle tests (as a share of the fp32
walk's), DRAM bytes per ray and Mrays/s against fp32, and the box pipelines' energy per test and
area against fp32 (docs/energy_area.md, "Reduced-precision box pipeline"). Every run must have
zero hit and work mismatches (the reference work is checked, the extra walk counted apart).

Published anchors: Keely 2014 ("Reduced Precision for Hardware Ray Tracing in GPUs", HPG): a
compact traversal unit from reduced-precision box arithmetic; Vaidyanathan et al. 2016
("Watertight Ray Traversal with Reduced Precision", HPG): the conservative rounding that keeps it
watertight.

Runs are cached in OUT (a run folder with a stats.json is reused; --fresh redoes them). Writes
OUT/study.json and, with --write-docs, the table between the `rp_boxes_table` markers of
docs/accel.md. Usage:

    python scripts/rpbox_study.py [--out out/rpbox_study] [--resolution 96x72]
        [--scenes sponza,hairball,cornell] [--accels bvh2,cwbvh8] [--bits 16,12,8,6,4]
        [--detailed-bits 8] [--jobs 2] [--write-docs]
"""

from __future__ import annotations

import argparse
import platform
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "scripts"))
from shortstack_study import make_trace, save_and_print, simulate  # noqa: E402  (the same trace and run cache)


def points(bits: list[int], detailed_bits: int) -> list[tuple[str, list[str], bool]]:
    """(run name, --set assignments, detailed-only): fp32, each width, the detailed pair."""
    out = [("fp32", ["traversal.box_precision_bits=0"], False)]
    out += [(f"b{b}", [f"traversal.box_precision_bits={b}"], False) for b in bits]
    if detailed_bits:
        for name, b in (("fp32-detailed", 0), (f"b{detailed_bits}-detailed", detailed_bits)):
            out.append((name, ["fidelity=detailed", f"traversal.box_precision_bits={b}"], True))
    return out


def row(
    scene: str, accel: str, name: str, stats: dict[str, Any], fp32: dict[str, Any]
) -> dict[str, Any]:
    s, f = stats["summary"], fp32["summary"]
    bp = stats.get("box_precision") or {}
    per_ray = bp.get("per_ray") or {}
    area, fp32_area = stats["area"]["mm2"]["box"], fp32["area"]["mm2"]["box"]
    return {
        "scene": scene,
        "accel": accel,
        "run": name,
        "fidelity": "detailed" if name.endswith("-detailed") else "approx",
        "bits": bp.get("bits", 23),
        "rays": s["rays"],
        "box_hits_per_ray": per_ray.get("box_hits", 0.0),
        "extra_steps": bp.get("extra_steps_fraction", 0.0),
        "extra_box_tests": bp.get("extra_box_tests_fraction", 0.0),
        "extra_tri_tests": bp.get("extra_tri_tests_fraction", 0.0),
        "dram_bytes_per_ray": s["dram_bytes_per_ray"],
        "dram_vs_fp32": s["dram_bytes_per_ray"] / f["dram_bytes_per_ray"],
        "mrays_per_second": s["mrays_per_second"],
        "speed_vs_fp32": s["mrays_per_second"] / f["mrays_per_second"],
        "box_test_pj": stats["energy"]["op_pj"]["box"],
        "box_test_pj_vs_fp32": stats["energy"]["op_pj"]["box"] / fp32["energy"]["op_pj"]["box"],
        "box_mm2": area,
        "box_mm2_vs_fp32": area / fp32_area,
        "box_nj_per_ray": stats["energy"]["per_ray_nj"]["box"],
        "box_energy_vs_fp32": stats["energy"]["per_ray_nj"]["box"]
        / fp32["energy"]["per_ray_nj"]["box"],
        "energy_vs_fp32": (stats["summary"].get("energy_per_ray_nj") or 0)
        / (fp32["summary"].get("energy_per_ray_nj") or 1),
    }


def run_study(args: argparse.Namespace) -> dict[str, Any]:
    t0 = time.time()
    combos = [(sc, ac) for sc in args.scenes for ac in args.accels]
    traces = {c: make_trace(*c, args) for c in combos}
    jobs = [
        (c, name, sets)
        for c in combos
        for name, sets, detailed in points(args.bits, args.detailed_bits)
        if not detailed or c == combos[0]
    ]
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        stats = list(pool.map(lambda j: simulate(traces[j[0]], j[1], j[2], args), jobs))
    by = {(j[0], j[1]): st for j, st in zip(jobs, stats, strict=True)}
    rows = []
    for c, name, _ in jobs:
        base = "fp32-detailed" if name.endswith("-detailed") else "fp32"
        rows.append(row(*c, name, by[(c, name)], by[(c, base)]))
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
        f"Generated by `scripts/rpbox_study.py` on {study['host']} ({study['date']}): "
        f"{study['workload']} rays at {study['resolution']}, default config (approx; the detailed "
        f"rows at fidelity detailed), one run per point; {len(rows)} runs in "
        f"{study['wall_seconds']} s, every one with zero hit and work mismatches. Bits: explicit "
        f"mantissa bits of the box tests (fp32: 23). Box hits: boxes per ray the fp32 walk does "
        f"not enter; extra steps, box and triangle tests: the extra walk over the fp32 walk's; "
        f"DRAM and speed against fp32 at the same fidelity; box test and box area: one test's "
        f"energy and the box pipelines' area against fp32's; box energy: the box pipelines' "
        f"energy per ray (extra tests included) against fp32's.",
        "",
        "| scene | structure | fidelity | bits | box hits/ray | extra steps | extra box tests "
        "| extra tri tests | DRAM | speed | box test | box area | box energy |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        bits = "fp32" if r["bits"] == 23 else str(r["bits"])
        lines.append(
            f"| {r['scene']} | {r['accel']} | {r['fidelity']} | {bits} "
            f"| {r['box_hits_per_ray']:.3f} | {pct(r['extra_steps'])} "
            f"| {pct(r['extra_box_tests'])} | {pct(r['extra_tri_tests'])} "
            f"| {r['dram_vs_fp32']:.3f}x | {r['speed_vs_fp32']:.3f}x "
            f"| {r['box_test_pj_vs_fp32']:.2f}x | {r['box_mm2_vs_fp32']:.2f}x "
            f"| {r['box_energy_vs_fp32']:.2f}x |"
        )
    return "\n".join(lines) + "\n"


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument("--out", type=Path, default=Path("out/rpbox_study"))
    p.add_argument("--resolution", default="96x72")
    p.add_argument("--workload", default="diffuse")
    p.add_argument("--scenes", default="sponza,hairball,cornell")
    p.add_argument("--accels", default="bvh2,cwbvh8")
    p.add_argument("--bits", default="16,12,8,6,4")
    p.add_argument("--detailed-bits", type=int, default=8, help="0: no detailed pair")
    p.add_argument("--hairball-triangles", type=int, default=50000)
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--fresh", action="store_true")
    p.add_argument("--write-docs", action="store_true")
    args = p.parse_args(argv)
    args.scenes = args.scenes.split(",")
    args.accels = args.accels.split(",")
    args.bits = [int(x) for x in args.bits.split(",")]
    return args


def main(argv: list[str] | None = None) -> None:
    args = parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    study = run_study(args)
    save_and_print(study, table(study), args, "rp_boxes_table")


if __name__ == "__main__":
    main()
