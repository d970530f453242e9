"""The field's own baseline (docs/presets.md, "The Vulkan-Sim baseline"): the RT unit of an RTX
2060 as Vulkan-Sim models it (`vulkansim_rtx2060`: warps of 32 rays, 4 per unit, over the 6-wide
compressed BVH Vulkan-Sim traverses), beside the same resources on MIMD units (`rtx2060`), on
diffuse rays of Sponza and a procedural hairball, each on the binary BVH and on cwbvh6; on the
warp baseline also Chou, Nowicki & Aamodt's treelet prefetching (MICRO 2023: the treelet
partition drives only the prefetcher, no treelet queues) and treelet scheduling with and without
prefetching. Table between the `vulkansim-baseline` markers of docs/presets.md; the prefetching
row between the `papers-treelet-prefetch-warp` markers of docs/papers.md; figure
docs/vulkansim_baseline.png."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from rtsim.study import Figure, Study, StudyRun, Table
from rtsim.study.tables import bvh_bytes_per_ray, fmt, prefetch_totals, scene

SCENES = ["sponza", "hairball"]
ACCELS = ["bvh2", "cwbvh6"]
#: Stack entries TTP prefetches per trigger (traversal.stack_prefetch): the top two, the next
#: pops of an upward walk.
TTP_ENTRIES = 2
#: (label, preset, --set over it); the first is the baseline each row is against, except MIMD
#: points, which are against the MIMD point.
POINTS: list[tuple[str, str, dict[str, Any]]] = [
    ("warp baseline", "vulkansim_rtx2060", {}),
    ("warp + treelet prefetch", "vulkansim_rtx2060", {"treelets.prefetch": True}),
    ("warp + treelets", "vulkansim_rtx2060", {"treelets.enabled": True}),
    (
        "warp + treelets + prefetch",
        "vulkansim_rtx2060",
        {"treelets.enabled": True, "treelets.prefetch": True},
    ),
    ("warp + CoopRT", "vulkansim_rtx2060", {"traversal.simt.cooperative": True}),
    ("warp + TTP", "vulkansim_rtx2060", {"traversal.stack_prefetch": TTP_ENTRIES}),
    ("MIMD, same resources", "rtx2060", {}),
    ("MIMD + TTP", "rtx2060", {"traversal.stack_prefetch": TTP_ENTRIES}),
]
QUICK = ["warp baseline", "warp + treelet prefetch", "warp + CoopRT", "warp + TTP", "MIMD, same resources"]


def specs(o: dict[str, Any]) -> list[dict[str, Any]]:
    points = [
        {"label": label, "preset": preset, "set": sets}
        for label, preset, sets in POINTS
        if not o["short"] or label in QUICK
    ]
    return [
        {
            "name": f"vulkansim-baseline-{s}",
            "scenes": [scene(s, o["hairball_triangles"])],
            "workloads": [{"name": "diffuse", "rays": ["diffuse"], "resolution": o["resolution"]}],
            "accel": ACCELS,
            "points": points,
        }
        for s in SCENES
    ]


def rows(run: StudyRun) -> list[dict[str, Any]]:
    out = []
    for r in run.rows():
        pf, rays = r["prefetch"], r["rays"]
        out.append(
            {
                "scene": r["scene"],
                "accel": r["accel"],
                "point": r["point"],
                "mrays_per_second": r["mrays_per_second"],
                "bvh_bytes_per_ray": r["bvh_bytes_per_ray"],
                "dram_utilization": r["dram_bandwidth_utilization"],
                "simd_efficiency": r.get("simd_efficiency"),
                "l1_hit_rate": r.get("l1_hit_rate"),
                "prefetch_per_ray": pf["issued"] / rays if pf.get("issued") else None,
                "prefetch_useful": pf["useful"] / pf["issued"] if pf.get("issued") else None,
                "area_mm2": r.get("area_mm2"),
                "hit_mismatches": r["hit_mismatches"],
            }
        )
    order = {p[0]: i for i, p in enumerate(POINTS)}
    out.sort(key=lambda x: (SCENES.index(x["scene"]), x["accel"], order[x["point"]]))
    return out


def _base(rs: list[dict[str, Any]], r: dict[str, Any]) -> dict[str, Any]:
    base = "MIMD, same resources" if r["point"] == "MIMD + TTP" else POINTS[0][0]
    return next(
        b
        for b in rs
        if b["scene"] == r["scene"] and b["accel"] == r["accel"] and b["point"] == base
    )


def _note(run: StudyRun) -> str:
    o, m = run.options, run.measured()
    return (
        f"Measured with `{run.command}` (diffuse rays at {o['resolution']}, hairball "
        f"{o['hairball_triangles']:,} triangles, `approx`; rtsim-sim git {m['git']}; "
        f"{m['date']}). One run per point (the model is deterministic); each row against the "
        "warp baseline on the same structure.\n\n"
    )


def table(run: StudyRun) -> str:
    rs = rows(run)
    out = [
        "| scene | structure | config | Mrays/s | vs warp baseline | BVH B/ray | L1 hit | "
        "DRAM busy | SIMD eff. | prefetched lines/ray | useful | hit mismatches |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rs:
        b = _base(rs, r)
        ratio = "" if b is r else f"{r['mrays_per_second'] / b['mrays_per_second']:.2f}x"
        useful = "-" if r["prefetch_useful"] is None else f"{100 * r['prefetch_useful']:.0f}%"
        out.append(
            f"| {r['scene']} | {r['accel']} | {r['point']} | {r['mrays_per_second']:.0f} | "
            f"{ratio} | {r['bvh_bytes_per_ray']:.0f} | {fmt(r['l1_hit_rate'], '.2f')} | "
            f"{100 * r['dram_utilization']:.0f}% | {fmt(r['simd_efficiency'], '.2f')} | "
            f"{fmt(r['prefetch_per_ray'], '.1f')} | {useful} | {r['hit_mismatches']} |"
        )
    return _note(run) + "\n".join(out) + "\n"


#: (technique, published figure, point on the warp baseline, point on MIMD or None).
PAPER_ROWS = [
    (
        "treelet prefetching, no treelet queues (Chou, Nowicki & Aamodt 2023)",
        "+32.1% average",
        "warp + treelet prefetch",
        None,
    ),
    (
        "cooperative lanes, `traversal.simt.cooperative` (CoopRT, ISCA 2025)",
        "2.15x geometric mean, up to 5.11x",
        "warp + CoopRT",
        None,
    ),
    (
        "stack-driven prefetching, `traversal.stack_prefetch` (TTP, Tozlu, Naithani & Zhou 2026)",
        "1.48x average, up to 1.89x; 98.92% L1 accuracy, 31.54% coverage",
        "warp + TTP",
        "MIMD + TTP",
    ),
]


def _ratios(rs: list[dict[str, Any]], point: str | None) -> str:
    if point is None:
        return "- (a warp technique)"
    cells = []
    for r in rs:
        if r["point"] == point and r["accel"] == "cwbvh6":
            b = _base(rs, r)
            cell = f"{r['scene']} {r['mrays_per_second'] / b['mrays_per_second']:.2f}x"
            if r["prefetch_useful"] is not None:
                cell += f" ({100 * r['prefetch_useful']:.0f}% of prefetches used)"
            cells.append(cell)
    return ", ".join(cells) or "not run"


def papers_row(run: StudyRun) -> str:
    """Each warp technique on the warp baseline beside its paper, and on MIMD units."""
    rs = rows(run)
    out = [
        "| technique | published (Vulkan-Sim) | ours on `vulkansim_rtx2060`, cwbvh6 "
        "| ours on `rtx2060` (MIMD), cwbvh6 |",
        "|---|---|---|---|",
    ]
    for name, published, warp, mimd in PAPER_ROWS:
        out.append(f"| {name} | {published} | {_ratios(rs, warp)} | {_ratios(rs, mimd)} |")
    return _note(run) + "\n".join(out) + "\n"


def plot(run: StudyRun, path: Path) -> None:
    from rtsim.study.tables import pyplot

    rs = rows(run)
    plt = pyplot()
    labels = [p[0] for p in POINTS if any(r["point"] == p[0] for r in rs)]
    colors = {"bvh2": "#1f77b4", "cwbvh6": "#ff7f0e"}
    fig, axes = plt.subplots(1, len(SCENES), figsize=(12, 4.2), squeeze=False)
    width = 0.38
    for ax, sc in zip(axes[0], SCENES, strict=True):
        for i, (accel, color) in enumerate(colors.items()):
            group = {r["point"]: r for r in rs if r["scene"] == sc and r["accel"] == accel}
            xs = [j + (i - 0.5) * width for j in range(len(labels))]
            ax.bar(
                xs,
                [group[p]["mrays_per_second"] if p in group else 0 for p in labels],
                width,
                color=color,
                label=accel,
            )
        ax.set_title(f"{sc}: diffuse rays on the RTX 2060's resources", fontsize=10)
        ax.set_ylabel("Mrays/s")
        ax.set_xticks(range(len(labels)), labels, rotation=25, ha="right", fontsize=8)
        ax.grid(True, axis="y", alpha=0.3)
        ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    fig.suptitle(
        "The Vulkan-Sim-style warp baseline, its treelet techniques, and MIMD", fontsize=12
    )
    fig.tight_layout(rect=(0, 0, 1, 0.94))
    fig.savefig(path, dpi=80)
    plt.close(fig)


STUDY = Study(
    name="vulkansim_baseline",
    about="the Vulkan-Sim-style warp baseline with treelet prefetching, beside MIMD units",
    specs=specs,
    tables=[
        Table("presets.md", "vulkansim-baseline", table),
        Table("papers.md", "papers-treelet-prefetch-warp", papers_row),
    ],
    figures=[Figure("vulkansim_baseline.png", plot)],
    options={"resolution": "320x240", "hairball_triangles": 200_000, "short": False},
    quick={"resolution": "32x24", "hairball_triangles": 20_000, "short": True},
    extra={"bvh_bytes_per_ray": bvh_bytes_per_ray, "prefetch": prefetch_totals},
)
