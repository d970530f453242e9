"""Execution models (docs/execution_models.md): MIMD units against SIMT warps of 8, 16 and 32
lanes, with and without ray sorting at dispatch, on Cornell, hairball and Sponza, primary and
diffuse rays.

Traces each scene's primary and diffuse rays once (`rtsim trace --workload primary|diffuse`),
replays every trace under each configuration with `rtsim-sim` at the approx level (every hit and
every ray's work checked), and writes:

- OUT/execution_models.json: one row per run (scene, rays, model, lanes, sort, Mrays/s, DRAM
  bytes per ray, SIMD efficiency, mismatches, ...);
- the table between the execution-models markers of the doc (with --doc);
- a figure (--figure, e.g. docs/execution_models.png): Mrays/s relative to MIMD and SIMD
  efficiency per scene and ray kind.

All runs share one machine: 8 units x 64 ray contexts (MIMD: 64 independent contexts; SIMT:
64 / lanes warps), rays dealt to units 64 at a time (dispatch.block_rays), the default
pipelines, caches and DRAM; only the traversal.model, lanes, SIMT policies and dispatch.sort
change.

    python scripts/execution_models_study.py --out out/execution_models \\
        [--resolution 64x48] [--doc docs/execution_models.md] [--figure docs/execution_models.png]
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import shutil
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from rtsim.doc_markers import write_between
from rtsim.launcher import SimJob, run_sim

#: (label, scene, extra trace arguments); Sponza only when the shared scenes are there.
SCENES = [
    ("cornell", "cornell", []),
    ("hairball", "hairball", ["--hairball-triangles", "50000"]),
    ("sponza", "sponza", []),
]
KINDS = ["primary", "diffuse"]
CONTEXTS = 64
BLOCK = 64
#: (model, lanes, sort, SIMT policy, refill)
CONFIGS = [("mimd", 0, "none", "", ""), ("mimd", 0, "origin_direction", "", "")]
CONFIGS += [
    ("simt", lanes, sort, "while_while", "lane")
    for sort in ("none", "origin_direction")
    for lanes in (8, 16, 32)
]
CONFIGS += [("simt", 32, "none", "if_if", "lane"), ("simt", 32, "none", "while_while", "warp")]


def trace(
    label: str, scene: str, extra: list[str], kind: str, args: argparse.Namespace, res: str = ""
) -> Path:
    res = res or args.resolution
    folder = (
        args.out / "traces" / f"{label}_{kind}"
        if res == args.resolution
        else (args.out / "traces" / f"{label}_{kind}_{res}")
    )
    if (folder / "trace.rtt").exists():
        return folder
    shutil.rmtree(folder, ignore_errors=True)
    cmd = [sys.executable, "-m", "rtsim", "trace", scene, "-o", str(folder),
           "--workload", kind, "--resolution", res, *extra]  # fmt: skip
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return folder


def run(
    folder: Path, config: tuple, args: argparse.Namespace, extra: tuple[str, ...] = ()
) -> dict[str, Any]:
    model, lanes, sort, policy, refill = config
    name = f"{folder.name}_{model}{lanes or ''}_{sort}_{policy}_{refill}" + "_".join(extra)
    sets = [f"traversal.model={model}", f"traversal.ray_contexts={CONTEXTS}",
            f"dispatch.sort={sort}", f"dispatch.block_rays={BLOCK}"]  # fmt: skip
    if lanes:
        sets += [f"traversal.simt.lanes={lanes}", f"traversal.simt.policy={policy}",
                 f"traversal.simt.refill={refill}"]  # fmt: skip
    sets += list(extra)
    result = run_sim(SimJob(trace=folder, out_dir=args.out / "runs" / name, sets=sets))
    if result.returncode != 0 or result.stats is None:
        raise SystemExit(f"{name}: rtsim-sim exit {result.returncode}: {result.stderr[-600:]}")
    s = result.stats["summary"]
    units = result.stats["model"]["units"].values()
    lane_req = sum(u.get("lane_requests", 0) for u in units)
    return {
        "trace": folder.name,
        "model": model,
        "lanes": lanes,
        "sort": sort,
        "policy": policy,
        "refill": refill,
        "rays": s["rays"],
        "mrays_per_second": s["mrays_per_second"],
        "dram_bytes_per_ray": s["dram_bytes_per_ray"],
        "simd_efficiency": s.get("simd_efficiency"),
        "coalesced_fraction": (
            sum(u["coalesced_requests"] for u in units) / lane_req if lane_req else None
        ),
        "l1_hit_rate": s["l1_hit_rate"],
        "energy_per_ray_nj": s.get("energy_per_ray_nj"),
        "hit_mismatches": s["hit_mismatches"],
        "work_mismatches": s["work_mismatches"],
        "bottleneck": s.get("bottleneck"),
    }


def config_label(row: dict[str, Any]) -> str:
    base = "MIMD" if row["model"] == "mimd" else f"SIMT {row['lanes']}"
    if row["policy"] == "if_if":
        base += " if-if"
    if row["refill"] == "warp":
        base += " warp refill"
    return base + (" + sort" if row["sort"] != "none" else "")


def table(rows: list[dict[str, Any]], args: argparse.Namespace) -> str:
    mismatches = sum(r["hit_mismatches"] + r["work_mismatches"] for r in rows)
    today = datetime.date.today().isoformat()
    lines = [
        f"Measured {today} on {platform.node()} ({os.cpu_count()} cores) by `python "
        f"scripts/execution_models_study.py --resolution {args.resolution}`: one `rtsim-sim` run "
        "per row at the approx level (deterministic: one run, no medians needed), 8 units x "
        f"{CONTEXTS} ray contexts, `dispatch.block_rays={BLOCK}` (a warp gets neighbouring rays), "
        "defaults otherwise; SIMT while-while with lane refill unless named; sort = "
        "`dispatch.sort=origin_direction`. "
        f"{len(rows)} runs, {mismatches} hit and work mismatches in all. Speed-up: Mrays/s "
        "against MIMD without sorting on the same trace.",
        "",
        "| trace | rays | config | Mrays/s | speed-up | DRAM B/ray | nJ/ray | SIMD eff. "
        "| requests after coalescing | L1 hit | bottleneck |",
        "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---|",
    ]
    base = {r["trace"]: r for r in rows if r["model"] == "mimd" and r["sort"] == "none"}
    for r in rows:
        simd = f"{r['simd_efficiency']:.2f}" if r["simd_efficiency"] is not None else "-"
        coal = f"{r['coalesced_fraction']:.2f}" if r["coalesced_fraction"] is not None else "-"
        speed = r["mrays_per_second"] / base[r["trace"]]["mrays_per_second"]
        nj = f"{r['energy_per_ray_nj']:.1f}" if r["energy_per_ray_nj"] is not None else "-"
        lines.append(
            f"| {r['trace']} | {r['rays']:,} | {config_label(r)} | {r['mrays_per_second']:.1f} | "
            f"{speed:.2f}x | {r['dram_bytes_per_ray']:.0f} | {nj} | {simd} | {coal} | "
            f"{r['l1_hit_rate']:.3f} | {r['bottleneck'] or '-'} |"
        )
    return "\n".join(lines) + "\n"


#: The sorting study: one larger trace, windows up to the whole trace.
SORT_WINDOWS = [4096, 65536]


def sorting_study(args: argparse.Namespace) -> str:
    """Sorting on a larger batch (Sponza diffuse): does a bigger window buy coherence?"""
    folder = trace("sponza", "sponza", [], "diffuse", args, args.sort_resolution)
    lines = [
        f"Sponza diffuse at {args.sort_resolution}, same machine and method as above; "
        "`dispatch.sort_window` as given (4,096 is the default; `dispatch.chunk_rays` at least "
        "as large, since the stage sorts within a chunk).",
        "",
        "| config | window | rays | Mrays/s | speed-up from sorting | DRAM B/ray | SIMD eff. "
        "| mismatches |",
        "|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for model, lanes in (("mimd", 0), ("simt", 32)):
        config = (model, lanes, "none", "while_while" if lanes else "", "lane" if lanes else "")
        base = run(folder, config, args)
        rows = [(base, "-")]
        for window in SORT_WINDOWS:
            sorted_config = (*config[:2], "origin_direction", *config[3:])
            # The stage sorts within a chunk: the chunk at least as large as the window.
            sets = (f"dispatch.sort_window={window}", f"dispatch.chunk_rays={max(16384, window)}")
            rows.append((run(folder, sorted_config, args, sets), window))
        for r, window in rows:
            simd = f"{r['simd_efficiency']:.2f}" if r["simd_efficiency"] is not None else "-"
            lines.append(
                f"| {config_label(r)} | {window} | {r['rays']:,} | {r['mrays_per_second']:.1f} | "
                f"{r['mrays_per_second'] / base['mrays_per_second']:.2f}x | "
                f"{r['dram_bytes_per_ray']:.0f} | {simd} | "
                f"{r['hit_mismatches'] + r['work_mismatches']} |"
            )
    return "\n".join(lines) + "\n"


def trends(rows: list[dict[str, Any]]) -> str:
    """Our figures beside the published trends, per scene."""
    by = {(r["trace"], config_label(r)): r for r in rows}
    scenes = list(dict.fromkeys(r["trace"].rsplit("_", 1)[0] for r in rows))

    def eff(trace: str, cfg: str) -> str:
        return f"{by[(trace, cfg)]['simd_efficiency']:.2f}"

    def speed(trace: str, cfg: str, base: str) -> str:
        a, b = by[(trace, cfg)], by[(trace, base)]
        return f"{a['mrays_per_second'] / b['mrays_per_second']:.2f}x"

    lines = [
        "| scene | SIMD eff. SIMT 32, primary -> diffuse | SIMT 32 / MIMD, primary -> diffuse "
        "| sorting, MIMD diffuse | sorting, SIMT 32 diffuse | SIMD eff. SIMT 32 diffuse, "
        "sorted |",
        "|---|---|---|---:|---:|---:|",
    ]
    for sc in scenes:
        p, d = f"{sc}_primary", f"{sc}_diffuse"
        if (p, "MIMD") not in by or (d, "MIMD") not in by:
            continue
        lines.append(
            f"| {sc} | {eff(p, 'SIMT 32')} -> {eff(d, 'SIMT 32')} | "
            f"{speed(p, 'SIMT 32', 'MIMD')} -> {speed(d, 'SIMT 32', 'MIMD')} | "
            f"{speed(d, 'MIMD + sort', 'MIMD')} | {speed(d, 'SIMT 32 + sort', 'SIMT 32')} | "
            f"{eff(d, 'SIMT 32 + sort')} |"
        )
    lines.append(
        "| published | Aila & Laine 2009: high on primary rays, falling on diffuse | "
        "SIMT GPUs hide divergence with many more warps per core than here | "
        "Boulos et al. 2008, packet reordering: about 1.5x on diffuse paths | "
        "Meister et al. 2020, sorting: 1.3-2.0x on incoherent rays | |"
    )
    return "\n".join(lines) + "\n"


def plot_against_mimd(
    rows: list[dict[str, Any]],
    path: Path,
    label_of: Callable[[dict[str, Any]], str],
    title: str,
    efficiency_title: str,
) -> None:
    """Bars per trace and configuration: Mrays/s over the MIMD row's of the same trace (top) and,
    for configurations that report it, SIMD efficiency (bottom)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    traces = list(dict.fromkeys(r["trace"] for r in rows))
    configs = list(dict.fromkeys(label_of(r) for r in rows))
    base = {r["trace"]: r["mrays_per_second"] for r in rows if label_of(r) == "MIMD"}
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9.5, 7.0), sharex=True)
    width = 0.8 / len(configs)
    colors = plt.get_cmap("tab10")
    for i, cfg in enumerate(configs):
        xs = [t + (i - (len(configs) - 1) / 2) * width for t in range(len(traces))]
        by = {r["trace"]: r for r in rows if label_of(r) == cfg}
        top.bar(
            xs,
            [by[t]["mrays_per_second"] / base[t] for t in traces],
            width,
            label=cfg,
            color=colors(i),
        )
        if by[traces[0]]["simd_efficiency"] is not None:
            bottom.bar(xs, [by[t]["simd_efficiency"] for t in traces], width, color=colors(i))
    top.axhline(1.0, color="black", linewidth=0.8)
    top.set_ylabel("Mrays/s / MIMD's")
    top.set_title(title)
    ymax = max(r["mrays_per_second"] / base[r["trace"]] for r in rows)
    top.set_ylim(0, max(1.45, ymax * 1.35))  # room for the legend above the bars
    top.legend(ncol=4, fontsize=8, loc="upper center")
    bottom.set_ylabel("SIMD efficiency")
    bottom.set_ylim(0, 1)
    bottom.set_xticks(range(len(traces)))
    bottom.set_xticklabels(traces, fontsize=8)
    bottom.set_title(efficiency_title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot(rows: list[dict[str, Any]], path: Path) -> None:
    plot_against_mimd(
        rows,
        path,
        config_label,
        "Execution models: throughput against MIMD (8 units x 64 ray contexts)",
        "SIMT: active lanes / lane slots",
    )


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, required=True)
    p.add_argument("--resolution", default="64x48")
    p.add_argument(
        "--doc", type=Path, help="write the table into this file's execution-models markers"
    )
    p.add_argument("--figure", type=Path, help="write the figure here (PNG)")
    p.add_argument("--replot", action="store_true", help="redraw from OUT/execution_models.json")
    p.add_argument("--sort-resolution", default="256x192", help="the sorting study's trace")
    p.add_argument("--no-sort-study", action="store_true")
    args = p.parse_args(argv)
    if args.replot:
        rows = json.loads((args.out / "execution_models.json").read_text())
        if args.figure:
            plot(rows, args.figure)
        return 0
    args.out.mkdir(parents=True, exist_ok=True)
    scenes_dir = Path(os.environ.get("RTSIM_SCENES", ""))
    rows = []
    for label, scene, extra in SCENES:
        if label == "sponza" and not (scenes_dir / "sponza").is_dir():
            print("sponza skipped: RTSIM_SCENES has no sponza", file=sys.stderr)
            continue
        for kind in KINDS:
            folder = trace(label, scene, extra, kind, args)
            for config in CONFIGS:
                rows.append(run(folder, config, args))
                print(json.dumps(rows[-1]), file=sys.stderr)
    (args.out / "execution_models.json").write_text(json.dumps(rows, indent=2))
    text = table(rows, args)
    print(text)
    trend_text = trends(rows)
    print(trend_text)
    if args.doc:
        write_between(args.doc, "execution-models", text)
        write_between(args.doc, "execution-models-trends", trend_text)
    if not args.no_sort_study and (scenes_dir / "sponza").is_dir():
        sort_text = sorting_study(args)
        print(sort_text)
        if args.doc:
            write_between(args.doc, "execution-models-sorting", sort_text)
    if args.figure:
        plot(rows, args.figure)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
