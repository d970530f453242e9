#!/usr/bin/env python3
"""The treelet study (docs/treelets.md): Sponza and a procedural hairball, primary and
diffuse rays, simulated with the baseline (treelets off) and with treelet scheduling at several
ray-buffer sizes and two treelet budgets, default config otherwise. Collects DRAM bytes per ray
(total and BVH = node + triangle reads), L2 traffic, Mrays/s and the ray buffer's counters, checks
every run has zero hit mismatches, and writes the table into docs/treelets.md (between the
`treelet-study` markers) and the figure to docs/treelets.png. Runs are cached in the output folder
(a run folder with a stats.json is reused; --fresh re-simulates everything).

    python scripts/treelet_study.py [--out out/treelet_study] [--resolution 480x360] [--fresh]
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from rtsim.doc_markers import write_between
from rtsim.launcher import SimJob, run_sim

REPO = Path(__file__).resolve().parents[1]


@dataclass(frozen=True)
class Point:
    """One simulation: a trace and the treelet settings (None: baseline, treelets off)."""

    scene: str
    workload: str
    buffer_kib: int | None = None
    treelet_kib: int = 16
    in_flight: int = 0  # treelets.max_rays_in_flight (0: what the SRAM holds, no overflow)

    @property
    def name(self) -> str:
        if self.buffer_kib is None:
            return f"{self.scene}-{self.workload}-base"
        extra = f"-if{self.in_flight}" if self.in_flight else ""
        return f"{self.scene}-{self.workload}-tl{self.treelet_kib}-rb{self.buffer_kib}{extra}"

    def sets(self) -> list[str]:
        if self.buffer_kib is None:
            return []
        return [
            "treelets.enabled=true",
            f"treelets.buffer_kib={self.buffer_kib}",
            f"treelets.treelet_kib={self.treelet_kib}",
            f"treelets.max_rays_in_flight={self.in_flight}",
        ]


def make_trace(scene: str, workload: str, out: Path, args: argparse.Namespace) -> Path:
    folder = out / "traces" / f"{scene}-{workload}"
    params = {"resolution": args.resolution, "hairball_triangles": args.hairball_triangles}
    stamp = folder / "study_params.json"
    reusable = (folder / "trace.rtt").is_file() and stamp.is_file() and not args.fresh
    if reusable and json.loads(stamp.read_text()) == params:
        return folder
    shutil.rmtree(folder, ignore_errors=True)
    cmd = [sys.executable, "-m", "rtsim", "trace", scene, "-o", str(folder)]
    cmd += ["--workload", workload, "--resolution", args.resolution, "--threads", "0"]
    if scene == "hairball":
        cmd += ["--hairball-triangles", str(args.hairball_triangles)]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    stamp.write_text(json.dumps(params))
    return folder


def simulate(point: Point, trace: Path, out: Path, fresh: bool) -> dict[str, Any]:
    run = out / "runs" / point.name
    stats_file = run / "stats.json"
    if fresh or not stats_file.is_file():
        shutil.rmtree(run, ignore_errors=True)
        result = run_sim(SimJob(trace=trace, out_dir=run, sets=list(point.sets())))
        if result.returncode != 0:
            raise SystemExit(
                f"{point.name}: rtsim-sim exit {result.returncode}: {result.stderr[-600:]}"
            )
    return json.loads(stats_file.read_text())


def row(point: Point, stats: dict[str, Any]) -> dict[str, Any]:
    s, m = stats["summary"], stats["model"]
    rays = s["rays"]
    dram = m["dram"]["by_kind"]
    bvh = sum(dram.get(k, {}).get("read_bytes", 0) for k in ("node", "triangle"))
    rb = m.get("ray_buffer") or {}
    return {
        **asdict(point),
        "rays": rays,
        "dram_bytes_per_ray": s["dram_bytes_per_ray"],
        "bvh_bytes_per_ray": bvh / rays,
        "ray_buffer_dram_bytes_per_ray": sum(
            dram.get("ray_buffer", {}).get(k, 0) for k in ("read_bytes", "write_bytes")
        )
        / rays,
        "l2_reads_per_ray": m["l2"]["reads"] / rays,
        "l2_read_bytes_per_ray": m["l2"]["read_bytes"] / rays,
        "l1_hit_rate": s["l1_hit_rate"],
        "l2_hit_rate": s["l2_hit_rate"],
        "mrays_per_second": s["mrays_per_second"],
        "dram_bandwidth_utilization": s["dram_bandwidth_utilization"],
        "cycles": s["cycles"],
        "hit_mismatches": s["hit_mismatches"],
        "work_mismatches": s["work_mismatches"],
        "treelets": rb.get("treelets", {}).get("count"),
        "capacity_rays": rb.get("capacity_rays"),
        "avg_queue_rays_at_pick": rb.get("avg_queue_rays_at_pick"),
        "drain_pick_fraction": rb["drain_picks"] / rb["picks"] if rb.get("picks") else None,
        "parks_per_ray": rb["parked"] / rays if rb else None,
        "overflow_writes": rb.get("overflow_writes"),
        "git": stats["provenance"].get("git"),
        "wall_seconds": s["wall_seconds"],
    }


def kib(v: int) -> str:
    return f"{v // 1024} MiB" if v >= 1024 else f"{v} KiB"


def table(rows: list[dict[str, Any]]) -> str:
    base = {(r["scene"], r["workload"]): r for r in rows if r["buffer_kib"] is None}
    out = [
        "| scene | rays | config | DRAM B/ray | BVH B/ray | BVH vs base | L2 reads/ray | "
        "L2 read B/ray | Mrays/s | vs base | queue at pick | parks/ray | overflow writes | "
        "hit mismatches |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        b = base[(r["scene"], r["workload"])]
        if r["buffer_kib"] is None:
            config, dbvh, speed, queue, parks, ovf = "baseline", "", "", "", "", ""
        else:
            config = f"treelets {r['treelet_kib']} KiB, buffer {kib(r['buffer_kib'])}"
            if r["in_flight"]:
                config += f", {r['in_flight']:,} rays in flight"
            dbvh = f"{100 * (r['bvh_bytes_per_ray'] / b['bvh_bytes_per_ray'] - 1):+.0f}%"
            speed = f"{r['mrays_per_second'] / b['mrays_per_second']:.2f}x"
            queue = f"{r['avg_queue_rays_at_pick']:.0f}"
            parks = f"{r['parks_per_ray']:.1f}"
            ovf = f"{r['overflow_writes']:,}"
        out.append(
            f"| {r['scene']} | {r['workload']} ({r['rays']:,}) | {config} | "
            f"{r['dram_bytes_per_ray']:.0f} | {r['bvh_bytes_per_ray']:.0f} | {dbvh} | "
            f"{r['l2_reads_per_ray']:.1f} | {r['l2_read_bytes_per_ray']:.0f} | "
            f"{r['mrays_per_second']:.1f} | {speed} | {queue} | {parks} | {ovf} | "
            f"{r['hit_mismatches']} |"
        )
    return "\n".join(out) + "\n"


def plot(rows: list[dict[str, Any]], path: Path, scenes: list[str], title: str) -> None:
    buffers = sorted({r["buffer_kib"] for r in rows if r["buffer_kib"]})
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    colors = {"primary": "#1f77b4", "diffuse": "#d62728"}
    styles = {16: ("-", "o"), 32: (":", "s")}
    fig, axes = plt.subplots(len(scenes), 2, figsize=(11, 4.0 * len(scenes)), squeeze=False)
    for (ax_dram, ax_speed), scene in zip(axes, scenes, strict=True):
        for workload, color in colors.items():
            group = [r for r in rows if r["scene"] == scene and r["workload"] == workload]
            base = next((r for r in group if r["buffer_kib"] is None), None)
            if base is None:
                continue
            for ax, key in ((ax_dram, "dram_bytes_per_ray"), (ax_speed, "mrays_per_second")):
                ax.axhline(base[key], color=color, ls="--", lw=1.2, label=f"{workload}, baseline")
                for tl, (ls, marker) in styles.items():
                    line = sorted(
                        (
                            r
                            for r in group
                            if r["buffer_kib"] and r["treelet_kib"] == tl and not r["in_flight"]
                        ),
                        key=lambda r: r["buffer_kib"],
                    )
                    if line:
                        ax.plot(
                            [r["buffer_kib"] for r in line],
                            [r[key] for r in line],
                            color=color,
                            ls=ls,
                            marker=marker,
                            ms=5,
                            label=f"{workload}, treelets {tl} KiB",
                        )
        rays = {r["workload"]: r["rays"] for r in rows if r["scene"] == scene}
        sub = ", ".join(f"{w} {n:,}" for w, n in rays.items())
        ax_dram.set_title(f"{scene}: DRAM traffic ({sub} rays)", fontsize=10)
        ax_dram.set_ylabel("DRAM bytes per ray (B)")
        ax_dram.set_ylim(bottom=0)
        ax_speed.set_title(f"{scene}: throughput at 1 GHz", fontsize=10)
        ax_speed.set_ylabel("Mrays/s")
        ax_speed.set_ylim(bottom=0)
        for ax in (ax_dram, ax_speed):
            ax.set_xscale("log", base=2)
            ax.set_xticks(buffers, [kib(b) for b in buffers])
            ax.xaxis.set_minor_locator(matplotlib.ticker.NullLocator())
            ax.set_xlabel("ray buffer SRAM (log scale)")
            ax.grid(True, which="major", alpha=0.3)
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=9, frameon=False)
    fig.suptitle(title, fontsize=12)
    fig.tight_layout(rect=(0, 0.07, 1, 0.97))
    fig.savefig(path, dpi=80)
    plt.close(fig)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, default=REPO / "out" / "treelet_study")
    p.add_argument("--resolution", default="480x360")
    p.add_argument("--hairball-triangles", type=int, default=200_000)
    p.add_argument("--buffers", default="128,512,2048,8192,32768", help="ray buffer KiB")
    p.add_argument("--budgets", default="16,32", help="treelet KiB (the second on diffuse only)")
    p.add_argument(
        "--overflow-rays",
        type=int,
        default=65536,
        help="rays in flight of the overflow run (512 KiB buffer, diffuse); 0: none",
    )
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--docs", type=Path, default=REPO / "docs")
    p.add_argument("--fresh", action="store_true", help="re-trace and re-simulate everything")
    args = p.parse_args()

    scenes, workloads = ["sponza", "hairball"], ["primary", "diffuse"]
    buffers = [int(b) for b in args.buffers.split(",")]
    budgets = [int(b) for b in args.budgets.split(",")]
    start = time.perf_counter()
    traces = {(s, w): make_trace(s, w, args.out, args) for s in scenes for w in workloads}
    points: list[Point] = []
    for s in scenes:
        for w in workloads:
            points.append(Point(s, w))
            for i, tl in enumerate(budgets):
                if i == 0 or w == "diffuse":
                    points += [Point(s, w, b, tl) for b in buffers]
            if w == "diffuse" and args.overflow_rays:
                points.append(Point(s, w, 512, budgets[0], args.overflow_rays))
    with ThreadPoolExecutor(args.workers) as pool:
        stats = list(
            pool.map(
                lambda pt: simulate(pt, traces[(pt.scene, pt.workload)], args.out, args.fresh),
                points,
            )
        )
    rows = [row(pt, st) for pt, st in zip(points, stats, strict=True)]
    bad = [r["scene"] + "-" + r["workload"] for r in rows if r["hit_mismatches"]]
    if bad:
        raise SystemExit(f"hit mismatches in {bad}")
    (args.out / "results.json").write_text(json.dumps(rows, indent=1))
    gits = sorted({str(r["git"]) for r in rows})
    note = (
        f"Measured with `python scripts/treelet_study.py` (resolution {args.resolution}, hairball "
        f"{args.hairball_triangles:,} triangles, default config otherwise; rtsim-sim git "
        f'{", ".join(gits)}). BVH = node + triangle reads from DRAM; "queue at pick" = mean rays '
        "in the queue a unit picked; every run has 0 hit and 0 work mismatches.\n\n"
    )
    write_between(args.docs / "treelets.md", "treelet-study", note + table(rows))
    plot(
        rows,
        args.docs / "treelets.png",
        scenes,
        "Treelet scheduling vs baseline (dashed), default accelerator (8 units, 1 MiB L2)",
    )
    print(table(rows))
    print(
        f"{len(points)} simulations, {time.perf_counter() - start:.0f} s; "
        f"wrote {args.docs / 'treelets.md'} and {args.docs / 'treelets.png'}"
    )


if __name__ == "__main__":
    main()
