"""Packets beside MIMD single rays (docs/execution_models.md, "Packets"): packets of 4, 16 and 64
rays (Wald et al. 2001), the hybrid that splits low-occupancy packets into single rays (Benthin et
al. 2012), packets re-formed at dispatch by the sorting stage (Boulos et al. 2008's reordering,
at dispatch), and single rays on a binary and an 8-wide BVH (Wald, Benthin & Boulos 2008), on
Cornell, hairball and Sponza, primary and diffuse rays.

Uses the traces and the machine of scripts/execution_models_study.py (8 units x 64 ray contexts,
rays dealt 64 at a time), traces each scene once more with an 8-wide BVH, replays every trace
with `rtsim-sim` at the approx level (every hit and every ray's work checked: packets against the
reference packet loop) and writes:

- OUT/execution_models_packets.json: one row per run;
- the tables between the execution-models-packets markers of the doc (with --doc);
- a figure (--figure, e.g. docs/execution_models_packets.png).

    python scripts/execution_models_packets.py --out out/execution_models \\
        [--resolution 96x72] [--doc docs/execution_models.md] \\
        [--figure docs/execution_models_packets.png] [--replot]
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import sys
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from execution_models_study import BLOCK, CONTEXTS, KINDS, SCENES, plot_against_mimd, trace

from rtsim.doc_markers import write_between
from rtsim.launcher import SimJob, run_sim

SORT = "origin_direction"
#: (label, accel, model, lanes, split_below, sort)
CONFIGS = [
    ("MIMD", "bvh2", "mimd", 0, 0.0, "none"),
    ("MIMD bvh8", "bvh8", "mimd", 0, 0.0, "none"),
    ("packet 4", "bvh2", "packet", 4, 0.0, "none"),
    ("packet 16", "bvh2", "packet", 16, 0.0, "none"),
    ("packet 64", "bvh2", "packet", 64, 0.0, "none"),
    ("hybrid 16", "bvh2", "packet", 16, 0.5, "none"),
    ("hybrid 64", "bvh2", "packet", 64, 0.25, "none"),
    ("packet 16 + sort", "bvh2", "packet", 16, 0.0, SORT),
]


#: Packets on wide BVHs (--wide): (label, accel, model, lanes, split_below, sort, extra --set).
#: "box x16": a box pipeline as wide as the packet (box.width = 16 tests per issue) for every
#: configuration of the row, single rays included, so neither side has more box throughput;
#: "lanes": the hybrid's split rays walk at once on the packet's free lanes.
BOX16 = ["box.width=16"]
LANES = ["traversal.packet.split_walks=lanes"]
WIDE_CONFIGS = [
    ("MIMD", "bvh2", "mimd", 0, 0.0, "none", []),
    ("MIMD bvh4", "bvh4", "mimd", 0, 0.0, "none", []),
    ("MIMD bvh8", "bvh8", "mimd", 0, 0.0, "none", []),
    ("packet 16", "bvh2", "packet", 16, 0.0, "none", []),
    ("packet 16 bvh4", "bvh4", "packet", 16, 0.0, "none", []),
    ("packet 16 bvh8", "bvh8", "packet", 16, 0.0, "none", []),
    ("packet 4 bvh4", "bvh4", "packet", 4, 0.0, "none", []),
    ("MIMD bvh4, box x16", "bvh4", "mimd", 0, 0.0, "none", BOX16),
    ("packet 16 bvh4, box x16", "bvh4", "packet", 16, 0.0, "none", BOX16),
    ("packet 16 bvh8, box x16", "bvh8", "packet", 16, 0.0, "none", BOX16),
    ("hybrid 16 bvh4", "bvh4", "packet", 16, 0.5, "none", []),
    ("hybrid 16 bvh4, lanes", "bvh4", "packet", 16, 0.5, "none", LANES),
    ("hybrid 16, lanes", "bvh2", "packet", 16, 0.5, "none", LANES),
]
WIDE_SCENES = ("hairball", "sponza")


def run(folder: Path, config: tuple, args: argparse.Namespace) -> dict[str, Any]:
    label, accel, model, lanes, split, sort, *rest = config
    extra = rest[0] if rest else []
    name = f"{folder.name}_{label.replace(' ', '_').replace('+', 'plus').replace(',', '')}"
    sets = [f"traversal.model={model}", f"traversal.ray_contexts={CONTEXTS}",
            f"dispatch.sort={sort}", f"dispatch.block_rays={BLOCK}", *extra]  # fmt: skip
    if lanes:
        sets += [f"traversal.packet.lanes={lanes}", f"traversal.packet.split_below={split}"]
    result = run_sim(SimJob(trace=folder, out_dir=args.out / "packet_runs" / name, sets=sets))
    if result.returncode != 0 or result.stats is None:
        raise SystemExit(f"{name}: rtsim-sim exit {result.returncode}: {result.stderr[-600:]}")
    st = result.stats
    s = st["summary"]
    units = list(st["model"]["units"].values())
    tests = {
        k: sum(p["tests"] for p in st["model"].get(k, {}).values()) for k in ("box", "triangle")
    }
    packets = sum(u.get("packets", 0) for u in units)
    return {
        "trace": folder.name.replace("_bvh8", ""),
        "config": label,
        "accel": accel,
        "model": model,
        "lanes": lanes,
        "split_below": split,
        "sort": sort,
        "rays": s["rays"],
        "mrays_per_second": s["mrays_per_second"],
        "dram_bytes_per_ray": s["dram_bytes_per_ray"],
        "simd_efficiency": s.get("simd_efficiency"),
        "packet_occupancy": (
            sum(u["active_lanes"] for u in units) / max(1, sum(u["packet_steps"] for u in units))
            if packets
            else None
        ),
        "node_fetches_per_packet": (
            sum(u["packet_node_fetches"] for u in units) / packets if packets else None
        ),
        "split_packets": sum(u.get("packet_splits", 0) for u in units) / packets
        if packets
        else None,
        "box_tests_per_ray": tests["box"] / s["rays"],
        "tri_tests_per_ray": tests["triangle"] / s["rays"],
        "hit_mismatches": s["hit_mismatches"],
        "work_mismatches": s["work_mismatches"],
        "bottleneck": s.get("bottleneck"),
    }


def fmt(v: Any, spec: str) -> str:
    return "-" if v is None else format(v, spec)


def table(rows: list[dict[str, Any]], args: argparse.Namespace) -> str:
    mismatches = sum(r["hit_mismatches"] + r["work_mismatches"] for r in rows)
    lines = [
        f"Measured {datetime.date.today().isoformat()} on {platform.node()} ({os.cpu_count()} "
        f"cores) by `python scripts/execution_models_packets.py --resolution {args.resolution}`: "
        "one `rtsim-sim` run per row at the approx level (deterministic), the machine above (8 "
        f"units x {CONTEXTS} ray contexts: {CONTEXTS} // lanes packets per unit), binary BVH "
        "unless named; hybrid 16 splits below 0.5 of the packet's rays, hybrid 64 below 0.25; "
        "sort = "
        f"`dispatch.sort={SORT}`. {len(rows)} runs, {mismatches} hit and work mismatches in all "
        "(packet work checked against the reference packet loop). Speed-up: against MIMD on the "
        "binary BVH, same trace. Occupancy: active rays per packet step (SIMD eff. = occupancy / "
        "lanes).",
        "",
        "| trace | config | Mrays/s | speed-up | DRAM B/ray | occupancy | SIMD eff. | node fetches "
        "/ packet | split | box tests/ray | tri tests/ray | bottleneck |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|",
    ]
    base = {r["trace"]: r for r in rows if r["config"] == "MIMD"}
    for r in rows:
        speed = r["mrays_per_second"] / base[r["trace"]]["mrays_per_second"]
        lines.append(
            f"| {r['trace']} | {r['config']} | {r['mrays_per_second']:.1f} | {speed:.2f}x | "
            f"{r['dram_bytes_per_ray']:.0f} | {fmt(r['packet_occupancy'], '.1f')} | "
            f"{fmt(r['simd_efficiency'], '.2f')} | {fmt(r['node_fetches_per_packet'], '.0f')} | "
            f"{fmt(r['split_packets'], '.2f')} | {r['box_tests_per_ray']:.1f} | "
            f"{r['tri_tests_per_ray']:.1f} | {r['bottleneck'] or '-'} |"
        )
    return "\n".join(lines) + "\n"


def trends(rows: list[dict[str, Any]]) -> str:
    """Our figures beside the published packet trends, per scene."""
    by = {(r["trace"], r["config"]): r for r in rows}
    scenes = list(dict.fromkeys(r["trace"].rsplit("_", 1)[0] for r in rows))

    def speed(trace: str, cfg: str, base: str = "MIMD") -> str:
        if (trace, cfg) not in by or (trace, base) not in by:
            return "-"
        return (
            f"{by[(trace, cfg)]['mrays_per_second'] / by[(trace, base)]['mrays_per_second']:.2f}x"
        )

    def eff(trace: str, cfg: str) -> str:
        return fmt(by[(trace, cfg)]["simd_efficiency"], ".2f") if (trace, cfg) in by else "-"

    lines = [
        "| scene | packet 16 / MIMD, primary -> diffuse | SIMD eff. packet 16, primary -> "
        "diffuse | MIMD bvh8 / packet 16, diffuse | hybrid 16 / packet 16, diffuse | re-formed "
        "(sort) / packet 16, diffuse |",
        "|---|---|---|---:|---:|---:|",
    ]
    for sc in scenes:
        p, d = f"{sc}_primary", f"{sc}_diffuse"
        lines.append(
            f"| {sc} | {speed(p, 'packet 16')} -> {speed(d, 'packet 16')} | "
            f"{eff(p, 'packet 16')} -> {eff(d, 'packet 16')} | "
            f"{speed(d, 'MIMD bvh8', 'packet 16')} | {speed(d, 'hybrid 16', 'packet 16')} | "
            f"{speed(d, 'packet 16 + sort', 'packet 16')} |"
        )
    lines.append(
        "| published | Wald et al. 2001: packets win on coherent rays | occupancy falls on "
        "secondary rays | Wald, Benthin & Boulos 2008: single rays on a wide BVH competitive with "
        "packets on secondary rays | Benthin et al. 2012: the hybrid never loses to either | "
        "Boulos et al. 2008: about 1.5x from reordering on diffuse paths |"
    )
    return "\n".join(lines) + "\n"


def wide_table(rows: list[dict[str, Any]], args: argparse.Namespace) -> str:
    """Packets on wide BVHs beside MIMD and packets on the binary BVH (--wide)."""
    mismatches = sum(r["hit_mismatches"] + r["work_mismatches"] for r in rows)
    lines = [
        f"Measured {datetime.date.today().isoformat()} on {platform.node()} ({os.cpu_count()} "
        f"cores) by `python scripts/execution_models_packets.py --wide --resolution "
        f"{args.resolution}`: the machine above (8 units x {CONTEXTS} ray contexts), approx level; "
        "box x16: `box.width=16` (a box pipeline as wide as the packet, every configuration so "
        "marked); hybrid splits below 0.5 of the packet's rays, its split rays walking one after "
        "another on the packet's context, or with `lanes` at once on the packet's lanes "
        f"(`traversal.packet.split_walks=lanes`). {len(rows)} runs, {mismatches} hit and work "
        "mismatches in all (packet work checked against the reference packet loop of each "
        "structure). Speed-up: against MIMD on the binary BVH, same trace.",
        "",
        "| trace | config | Mrays/s | speed-up | vs packet 16 | DRAM B/ray | occupancy | SIMD eff. "
        "| node fetches / packet | split | box tests/ray | bottleneck |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|",
    ]
    base = {r["trace"]: r for r in rows if r["config"] == "MIMD"}
    pk16 = {r["trace"]: r for r in rows if r["config"] == "packet 16"}
    for r in rows:
        speed = r["mrays_per_second"] / base[r["trace"]]["mrays_per_second"]
        vs = r["mrays_per_second"] / pk16[r["trace"]]["mrays_per_second"]
        lines.append(
            f"| {r['trace']} | {r['config']} | {r['mrays_per_second']:.1f} | {speed:.2f}x | "
            f"{vs:.2f}x | {r['dram_bytes_per_ray']:.0f} | {fmt(r['packet_occupancy'], '.1f')} | "
            f"{fmt(r['simd_efficiency'], '.2f')} | {fmt(r['node_fetches_per_packet'], '.0f')} | "
            f"{fmt(r['split_packets'], '.2f')} | {r['box_tests_per_ray']:.1f} | "
            f"{r['bottleneck'] or '-'} |"
        )
    return "\n".join(lines) + "\n"


def measure_wide(args: argparse.Namespace) -> list[dict[str, Any]]:
    """WIDE_CONFIGS on hairball and Sponza, primary and diffuse (rows also in OUT/*_wide.json)."""
    args.out.mkdir(parents=True, exist_ok=True)
    scenes_dir = Path(os.environ.get("RTSIM_SCENES", ""))
    rows = []
    for label, scene, extra in SCENES:
        if label not in WIDE_SCENES:
            continue
        if label == "sponza" and not (scenes_dir / "sponza").is_dir():
            print("sponza skipped: RTSIM_SCENES has no sponza", file=sys.stderr)
            continue
        for kind in KINDS:
            folders = {
                "bvh2": trace(label, scene, extra, kind, args),
                "bvh4": trace(f"{label}_bvh4", scene, [*extra, "--accel", "bvh4"], kind, args),
                "bvh8": trace(f"{label}_bvh8", scene, [*extra, "--accel", "bvh8"], kind, args),
            }
            for config in WIDE_CONFIGS:
                row = run(folders[config[1]], config, args)
                row["trace"] = f"{label}_{kind}"
                rows.append(row)
                print(json.dumps(rows[-1]), file=sys.stderr)
    (args.out / "execution_models_packets_wide.json").write_text(json.dumps(rows, indent=2))
    return rows


def plot(rows: list[dict[str, Any]], path: Path) -> None:
    plot_against_mimd(
        rows,
        path,
        lambda r: str(r["config"]),
        "Packets against single rays (8 units x 64 ray contexts; MIMD: bvh2)",
        "packets: active rays per packet step / lanes",
    )


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, required=True)
    p.add_argument("--resolution", default="64x48")
    p.add_argument("--doc", type=Path, help="write the tables into this file's markers")
    p.add_argument("--figure", type=Path, help="write the figure here (PNG)")
    p.add_argument(
        "--replot",
        action="store_true",
        help="tables and figure from OUT/execution_models_packets.json",
    )
    p.add_argument(
        "--wide",
        action="store_true",
        help="packets on bvh4/bvh8 beside MIMD and packets on bvh2 (hairball, Sponza): the "
        "execution-models-packets-wide table",
    )
    args = p.parse_args(argv)
    if args.wide:
        data = args.out / "execution_models_packets_wide.json"
        rows = json.loads(data.read_text()) if args.replot else measure_wide(args)
        text = wide_table(rows, args)
        print(text)
        if args.doc:
            write_between(args.doc, "execution-models-packets-wide", text)
        return 0
    data = args.out / "execution_models_packets.json"
    rows = json.loads(data.read_text()) if args.replot else measure(args)
    text, trend_text = table(rows, args), trends(rows)
    print(text)
    print(trend_text)
    if args.doc:
        write_between(args.doc, "execution-models-packets", text)
        write_between(args.doc, "execution-models-packet-trends", trend_text)
    if args.figure:
        plot(rows, args.figure)
    return 0


def measure(args: argparse.Namespace) -> list[dict[str, Any]]:
    """Every configuration on every trace; the rows also go to OUT/execution_models_packets.json."""
    args.out.mkdir(parents=True, exist_ok=True)
    scenes_dir = Path(os.environ.get("RTSIM_SCENES", ""))
    rows = []
    for label, scene, extra in SCENES:
        if label == "sponza" and not (scenes_dir / "sponza").is_dir():
            print("sponza skipped: RTSIM_SCENES has no sponza", file=sys.stderr)
            continue
        for kind in KINDS:
            folders = {
                "bvh2": trace(label, scene, extra, kind, args),
                "bvh8": trace(f"{label}_bvh8", scene, [*extra, "--accel", "bvh8"], kind, args),
            }
            for config in CONFIGS:
                row = run(folders[config[1]], config, args)
                row["trace"] = f"{label}_{kind}"
                rows.append(row)
                print(json.dumps(rows[-1]), file=sys.stderr)
    (args.out / "execution_models_packets.json").write_text(json.dumps(rows, indent=2))
    return rows


if __name__ == "__main__":
    raise SystemExit(main())
