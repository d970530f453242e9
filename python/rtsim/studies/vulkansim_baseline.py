"""The field's own baseline (docs/presets.md, "The Vulkan-Sim baseline"): the RT unit of an RTX
2060 as Vulkan-Sim models it (`vulkansim_rtx2060`: warps of 32 rays, 4 per unit, over the 6-wide
compressed BVH Vulkan-Sim traverses), beside the same resources on MIMD units (`rtx2060`), on
diffuse rays of Sponza and a procedural hairball, each on the binary BVH and on cwbvh6; on the
warp baseline also Chou, Nowicki & Aamodt's treelet prefetching (MICRO 2023: the treelet
partition drives only the prefetcher, no treelet queues) and treelet scheduling with and without
prefetching, a short stack with a restart trail, ray sorting, cooperative lanes (CoopRT),
stack-driven prefetching (TTP), 10% sampling, cwbvh8 against bvh2 and, against the fp32 BVH6,
AQB8-style quantised box tests on cwbvh6. Table between the `vulkansim-baseline` markers of
docs/presets.md; the papers' rows (_vulkansim_papers.py), each with its measured reason, between
the `papers-treelet-prefetch-warp` markers of docs/papers.md; figure docs/vulkansim_baseline.png."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from rtsim.studies._vulkansim_papers import (
    MIMD,
    SAMPLED,
    SAMPLING_FULL,
    SCENES,
    WARP,
    base,
    find,
    note,
    papers_rows,
)
from rtsim.study import Figure, Study, StudyRun, Table
from rtsim.study.tables import (
    bvh_bytes_per_ray,
    cycle_uses,
    fmt,
    l1_misses,
    prefetch_totals,
    scene,
    stack_prefetch_totals,
    units,
)

ACCELS = ["bvh2", "cwbvh6"]
#: Stack entries TTP prefetches per trigger (traversal.stack_prefetch): the top two, the next
#: pops of an upward walk.
TTP_ENTRIES = 2
#: Ray sorting with a window as large as the 320x240 trace (docs/execution_models.md, "Sorting").
SORT = {
    "dispatch.sort": "origin_direction",
    "dispatch.sort_window": 65536,
    "dispatch.chunk_rays": 65536,
}
#: (label, preset, --set over it); the first is the baseline each row is against, except MIMD
#: points, which are against the MIMD point.
POINTS: list[tuple[str, str, dict[str, Any]]] = [
    (WARP, "vulkansim_rtx2060", {}),
    ("warp + treelet prefetch", "vulkansim_rtx2060", {"treelets.prefetch": True}),
    ("warp + treelets", "vulkansim_rtx2060", {"treelets.enabled": True}),
    (
        "warp + treelets + prefetch",
        "vulkansim_rtx2060",
        {"treelets.enabled": True, "treelets.prefetch": True},
    ),
    ("warp + CoopRT", "vulkansim_rtx2060", {"traversal.simt.cooperative": True}),
    ("warp + TTP", "vulkansim_rtx2060", {"traversal.stack_prefetch": TTP_ENTRIES}),
    (
        "warp + short stack",
        "vulkansim_rtx2060",
        {"traversal.stack_overflow": "restart_trail", "traversal.stack_entries": 5},
    ),
    ("warp + ray sorting", "vulkansim_rtx2060", SORT),
    ("warp + 8-bit boxes", "vulkansim_rtx2060", {"traversal.box_precision_bits": 8}),
    (MIMD, "rtx2060", {}),
    ("MIMD + TTP", "rtx2060", {"traversal.stack_prefetch": TTP_ENTRIES}),
    ("MIMD + ray sorting", "rtx2060", SORT),
]
QUICK = [
    WARP,
    "warp + treelet prefetch",
    "warp + CoopRT",
    "warp + TTP",
    MIMD,
]
#: AQB8 against the fp32 6-wide BVH: the baselines on bvh6, the quantised box tests on cwbvh6.
AQB8 = {"traversal.quantized_boxes": True}
AQB8_BASE = [WARP, MIMD]
AQB8_POINTS = [("warp + AQB8", "vulkansim_rtx2060", AQB8), ("MIMD + AQB8", "rtx2060", AQB8)]
#: Sampling against Zatel on a trace large enough for a 10% sample to hold its clusters' warm-up
#: and measured rays (the warp baseline's 3,840 lanes need 30,720): the full run and the sample.
SAMPLING_POINTS = [
    (SAMPLING_FULL, "vulkansim_rtx2060", {}),
    (SAMPLED, "vulkansim_rtx2060", {"sampling.fraction": 0.1}),
]
#: cwbvh6 with compressed leaves (Benthin et al. 2018), as a spec's structure entry.
LEAVES = {"kind": "cwbvh6", "build": {"compressed_leaves": True}, "label": "cwbvh6+leaves"}
#: Every point label in table order.
LABELS = [p[0] for p in POINTS] + [p[0] for p in AQB8_POINTS] + [p[0] for p in SAMPLING_POINTS]


def _lane_totals(rec: Any) -> dict[str, int]:
    """The warp units' lane slots, active lanes and helper steps, summed."""
    out = {"lane_slots": 0, "active_lanes": 0, "helper": 0}
    for u in units(rec):
        out["lane_slots"] += u.get("lane_slots") or 0
        out["active_lanes"] += u.get("active_lanes") or 0
        out["helper"] += u.get("helper_steps") or 0
    return out


def _section(rec: Any, section: str, key: str) -> Any:
    """A key of one of stats.json's technique sections (None when the run has none)."""
    return ((rec.stats or {}).get(section) or {}).get(key)


def specs(o: dict[str, Any]) -> list[dict[str, Any]]:
    points = [
        {"label": label, "preset": preset, "set": sets}
        for label, preset, sets in POINTS
        if not o["short"] or label in QUICK
    ]
    base = {label: (preset, sets) for label, preset, sets in POINTS}

    def spec(
        name: str, s: str, accel: list[str], pts: list[dict[str, Any]], resolution: str = ""
    ) -> dict[str, Any]:
        res = resolution or o["resolution"]
        # Every point at the study's level (detailed: approx is 4-16% fast on these warps,
        # docs/fidelity.md "Across unit kinds and treelets").
        pts = [{**p, "set": {**p.get("set", {}), "fidelity": o["fidelity"]}} for p in pts]
        return {
            "name": f"{name}-{s}",
            "scenes": [scene(s, o["hairball_triangles"])],
            "workloads": [{"name": "diffuse", "rays": ["diffuse"], "resolution": res}],
            "accel": accel,
            "points": pts,
        }

    out = []
    for s in SCENES:
        out.append(spec("vulkansim-baseline", s, ACCELS, points))
        fp32 = [{"label": b, "preset": base[b][0], "set": base[b][1]} for b in AQB8_BASE]
        out.append(spec("vulkansim-aqb8-base", s, ["bvh6"], fp32))
        quantised = [{"label": label, "preset": p, "set": sets} for label, p, sets in AQB8_POINTS]
        out.append(spec("vulkansim-aqb8", s, ["cwbvh6"], quantised))
        # Ylitie et al.'s compressed 8-wide BVH against the binary one of the first spec, and
        # Benthin et al.'s compressed leaves under cwbvh6.
        out.append(spec("vulkansim-cwbvh8", s, ["cwbvh8"], fp32))
        out.append(spec("vulkansim-leaves", s, [LEAVES], fp32))
        if not o["short"]:
            sampled = [{"label": label, "preset": p, "set": st} for label, p, st in SAMPLING_POINTS]
            out.append(spec("vulkansim-sampling", s, ["cwbvh6"], sampled, o["sampling_resolution"]))
    return out


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
                "energy_nj": r.get("energy_per_ray_nj"),
                "dram_bytes_per_ray": r.get("dram_bytes_per_ray"),
                "l1_misses": r["l1_misses"],
                "uses": r["uses"],
                "stack_prefetch": r["stack_prefetch"],
                "lanes": r["lanes"],
                "extra_steps": r["extra_steps"],
                "restart_steps": r["restart_steps"],
                "restarts": r["restarts"],
                "wall_seconds": r.get("wall_seconds"),
                "prefetch_redundant": pf.get("redundant"),
                "hit_mismatches": r["hit_mismatches"],
                "work_mismatches": r["work_mismatches"],
            }
        )
    out.sort(key=lambda x: (SCENES.index(x["scene"]), x["accel"], LABELS.index(x["point"])))
    return out


def table(run: StudyRun) -> str:
    rs = rows(run)
    out = [
        "| scene | structure | config | Mrays/s | vs baseline | BVH B/ray | L1 hit | "
        "DRAM busy | SIMD eff. | prefetched lines/ray | useful | hit mismatches |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in (r for r in rs if r["point"] not in (SAMPLING_FULL, SAMPLED)):
        # The MIMD point is set against the warp baseline, the other MIMD points against it.
        b = find(rs, r["scene"], r["accel"], WARP) if r["point"] == MIMD else base(rs, r)
        speed = r["mrays_per_second"] / b["mrays_per_second"] if b else 0.0
        ratio = "" if b is r or b is None else f"{speed:.2f}x"
        useful = "-" if r["prefetch_useful"] is None else f"{100 * r['prefetch_useful']:.0f}%"
        out.append(
            f"| {r['scene']} | {r['accel']} | {r['point']} | {r['mrays_per_second']:.0f} | "
            f"{ratio} | {r['bvh_bytes_per_ray']:.0f} | {fmt(r['l1_hit_rate'], '.2f')} | "
            f"{100 * r['dram_utilization']:.0f}% | {fmt(r['simd_efficiency'], '.2f')} | "
            f"{fmt(r['prefetch_per_ray'], '.1f')} | {useful} | {r['hit_mismatches']} |"
        )
    return note(run) + "\n".join(out) + "\n"


def papers_row(run: StudyRun) -> str:
    return papers_rows(run, rows(run))


def plot(run: StudyRun, path: Path) -> None:
    from rtsim.study.tables import pyplot

    rs = rows(run)
    plt = pyplot()
    labels = [p[0] for p in POINTS if any(r["point"] == p[0] for r in rs)]
    rs = [r for r in rs if r["accel"] in ACCELS]  # the AQB8 comparison is a table of its own
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
        ax.legend(fontsize=8, loc="upper left")  # the warp points at the left are short
    fig.suptitle(
        "The Vulkan-Sim-style warp baseline, the techniques its papers study, and MIMD", fontsize=12
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
    options={
        "resolution": "320x240",
        "sampling_resolution": "1024x768",
        "fidelity": "detailed",
        "hairball_triangles": 200_000,
        "short": False,
    },
    quick={
        "resolution": "32x24",
        "hairball_triangles": 20_000,
        "short": True,
        "fidelity": "approx",
    },
    extra={
        "bvh_bytes_per_ray": bvh_bytes_per_ray,
        "prefetch": prefetch_totals,
        "l1_misses": l1_misses,
        "uses": cycle_uses,
        "stack_prefetch": stack_prefetch_totals,
        "lanes": _lane_totals,
        "extra_steps": lambda rec: _section(rec, "box_precision", "extra_steps_fraction"),
        "restart_steps": lambda rec: _section(rec, "short_stack", "extra_steps_fraction"),
        "restarts": lambda rec: (_section(rec, "short_stack", "per_ray") or {}).get("restarts"),
    },
)
