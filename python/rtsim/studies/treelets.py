"""The treelet study (docs/treelets.md): Sponza and a procedural hairball, primary and diffuse
rays, simulated with the baseline (treelets off) and with treelet scheduling at several
ray-buffer sizes and two treelet budgets (the second on diffuse rays only), default config
otherwise, plus one run that lets more rays into flight than the buffer holds (overflow to DRAM).
Table: DRAM bytes per ray (total and BVH = node + triangle reads), L2 traffic, Mrays/s and the
ray buffer's counters (between the `treelet-study` markers); figure: docs/treelets.png."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from rtsim.study import Figure, Study, StudyRun, Table
from rtsim.study.tables import bvh_bytes_per_ray, kib, pyplot, ray_buffer, scene

SCENES = ["sponza", "hairball"]
WORKLOADS = ["primary", "diffuse"]


def _point(buffer: int, treelet: int, in_flight: int = 0) -> dict[str, Any]:
    return {
        "label": f"tl{treelet}-rb{buffer}" + (f"-if{in_flight}" if in_flight else ""),
        "set": {
            "treelets.enabled": True,
            "treelets.buffer_kib": buffer,
            "treelets.treelet_kib": treelet,
            "treelets.max_rays_in_flight": in_flight,
        },
    }


def specs(o: dict[str, Any]) -> list[dict[str, Any]]:
    """One spec per scene and workload (the table's order): the baseline, then each budget's
    buffers (the second budget on diffuse only), then the overflow run (diffuse)."""
    out = []
    for s in SCENES:
        for w in WORKLOADS:
            points: list[dict[str, Any]] = [{"label": "base"}]
            for i, tl in enumerate(o["budgets"]):
                if i == 0 or w == "diffuse":
                    points += [_point(b, tl) for b in o["buffers"]]
            if w == "diffuse" and o["overflow_rays"]:
                points.append(_point(512, o["budgets"][0], o["overflow_rays"]))
            out.append(
                {
                    "name": f"treelets-{s}-{w}",
                    "scenes": [scene(s, o["hairball_triangles"])],
                    "workloads": [{"name": w, "rays": [w], "resolution": o["resolution"]}],
                    "points": points,
                }
            )
    return out


def rows(run: StudyRun) -> list[dict[str, Any]]:
    """The frame's rows in the table's terms (buffer_kib None: the baseline)."""
    out = []
    for r in run.rows():
        on = bool(r["treelets.enabled"])
        rays = r["rays"]
        out.append(
            {
                "scene": r["scene"],
                "workload": r["workload"],
                "buffer_kib": r["treelets.buffer_kib"] if on else None,
                "treelet_kib": r["treelets.treelet_kib"],
                "in_flight": r["treelets.max_rays_in_flight"],
                "rays": rays,
                "dram_bytes_per_ray": r["dram_bytes_per_ray"],
                "bvh_bytes_per_ray": r["bvh_bytes_per_ray"],
                "l2_reads_per_ray": r["l2_reads"] / rays,
                "l2_read_bytes_per_ray": r["l2_read_bytes"] / rays,
                "mrays_per_second": r["mrays_per_second"],
                "hit_mismatches": r["hit_mismatches"],
                "avg_queue_rays_at_pick": r["queue_at_pick"],
                "parks_per_ray": r["parked"] / rays if on else None,
                "overflow_writes": r["overflow_writes"],
            }
        )
    return out


def table(run: StudyRun) -> str:
    rs = rows(run)
    base = {(r["scene"], r["workload"]): r for r in rs if r["buffer_kib"] is None}
    out = [
        "| scene | rays | config | DRAM B/ray | BVH B/ray | BVH vs base | L2 reads/ray | "
        "L2 read B/ray | Mrays/s | vs base | queue at pick | parks/ray | overflow writes | "
        "hit mismatches |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rs:
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
    o = run.options
    note = (
        f"Measured with `{run.command}` (resolution {o['resolution']}, hairball "
        f"{o['hairball_triangles']:,} triangles, default config otherwise; rtsim-sim git "
        f'{run.measured()["git"]}). BVH = node + triangle reads from DRAM; "queue at pick" = '
        "mean rays in the queue a unit picked; every run has 0 hit and 0 work mismatches.\n\n"
    )
    return note + "\n".join(out) + "\n"


def plot(run: StudyRun, path: Path) -> None:
    rs = rows(run)
    buffers = sorted({r["buffer_kib"] for r in rs if r["buffer_kib"]})
    plt = pyplot()
    import matplotlib.ticker

    colors = {"primary": "#1f77b4", "diffuse": "#d62728"}
    styles = {16: ("-", "o"), 32: (":", "s")}
    fig, axes = plt.subplots(len(SCENES), 2, figsize=(11, 4.0 * len(SCENES)), squeeze=False)
    for (ax_dram, ax_speed), sc in zip(axes, SCENES, strict=True):
        for workload, color in colors.items():
            group = [r for r in rs if r["scene"] == sc and r["workload"] == workload]
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
        rays = {r["workload"]: r["rays"] for r in rs if r["scene"] == sc}
        sub = ", ".join(f"{w} {n:,}" for w, n in rays.items())
        ax_dram.set_title(f"{sc}: DRAM traffic ({sub} rays)", fontsize=10)
        ax_dram.set_ylabel("DRAM bytes per ray (B)")
        ax_dram.set_ylim(bottom=0)
        ax_speed.set_title(f"{sc}: throughput at 1 GHz", fontsize=10)
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
    fig.suptitle(
        "Treelet scheduling vs baseline (dashed), default accelerator (8 units, 1 MiB L2)",
        fontsize=12,
    )
    fig.tight_layout(rect=(0, 0.07, 1, 0.97))
    fig.savefig(path, dpi=80)
    plt.close(fig)


STUDY = Study(
    name="treelets",
    about="treelet scheduling against the baseline over ray-buffer sizes and treelet budgets",
    specs=specs,
    tables=[Table("treelets.md", "treelet-study", table)],
    figures=[Figure("treelets.png", plot)],
    options={
        "resolution": "320x240",
        "hairball_triangles": 200_000,
        "buffers": [128, 512, 2048, 8192, 32768],
        "budgets": [16, 32],
        "overflow_rays": 65536,
    },
    quick={
        "resolution": "32x24",
        "hairball_triangles": 20_000,
        "buffers": [128, 2048],
        "overflow_rays": 4096,
    },
    extra={
        "bvh_bytes_per_ray": bvh_bytes_per_ray,
        "l2_reads": "model.l2.reads",
        "l2_read_bytes": "model.l2.read_bytes",
        "queue_at_pick": lambda r: ray_buffer(r).get("avg_queue_rays_at_pick"),
        "parked": lambda r: ray_buffer(r).get("parked"),
        "overflow_writes": lambda r: ray_buffer(r).get("overflow_writes"),
    },
)
