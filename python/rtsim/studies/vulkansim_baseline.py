"""The field's own baseline (docs/presets.md, "The Vulkan-Sim baseline"): the RT unit of an RTX
2060 as Vulkan-Sim models it (`vulkansim_rtx2060`: warps of 32 rays, 4 per unit, over the 6-wide
compressed BVH Vulkan-Sim traverses), beside the same resources on MIMD units (`rtx2060`), on
diffuse rays of Sponza and a procedural hairball, each on the binary BVH and on cwbvh6; on the
warp baseline also Chou, Nowicki & Aamodt's treelet prefetching (MICRO 2023: the treelet
partition drives only the prefetcher, no treelet queues) and treelet scheduling with and without
prefetching, cooperative lanes (CoopRT), stack-driven prefetching (TTP) and, against the fp32
BVH6, AQB8-style quantised box tests on cwbvh6. Table between the `vulkansim-baseline` markers
of docs/presets.md; the papers' rows, each with its measured reason, between the
`papers-treelet-prefetch-warp` markers of docs/papers.md; figure docs/vulkansim_baseline.png."""

from __future__ import annotations

from pathlib import Path
from typing import Any

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
QUICK = [
    "warp baseline",
    "warp + treelet prefetch",
    "warp + CoopRT",
    "warp + TTP",
    "MIMD, same resources",
]
#: AQB8 against the fp32 6-wide BVH: the baselines on bvh6, the quantised box tests on cwbvh6.
AQB8 = {"traversal.quantized_boxes": True}
AQB8_BASE = ["warp baseline", "MIMD, same resources"]
AQB8_POINTS = [("warp + AQB8", "vulkansim_rtx2060", AQB8), ("MIMD + AQB8", "rtx2060", AQB8)]
#: Every point label in table order.
LABELS = [p[0] for p in POINTS] + [p[0] for p in AQB8_POINTS]
#: Context-cycle uses that wait on the memory hierarchy (docs/stats.md, cycle accounting).
MEMORY_USES = ("l1_hit", "l1_mshr_full", "l2", "l2_mshr_full", "dram", "stack")
#: Uses of lanes with nothing to step: waiting for their warp, for rays, or after the last.
IDLE_USES = ("idle_lane", "starved", "tail")


def _lane_totals(rec: Any) -> dict[str, int]:
    """The warp units' lane slots, active lanes and helper steps, summed."""
    out = {"lane_slots": 0, "active_lanes": 0, "helper": 0}
    for u in units(rec):
        out["lane_slots"] += u.get("lane_slots") or 0
        out["active_lanes"] += u.get("active_lanes") or 0
        out["helper"] += u.get("helper_steps") or 0
    return out


def specs(o: dict[str, Any]) -> list[dict[str, Any]]:
    points = [
        {"label": label, "preset": preset, "set": sets}
        for label, preset, sets in POINTS
        if not o["short"] or label in QUICK
    ]
    base = {label: (preset, sets) for label, preset, sets in POINTS}

    def spec(name: str, s: str, accel: list[str], pts: list[dict[str, Any]]) -> dict[str, Any]:
        return {
            "name": f"{name}-{s}",
            "scenes": [scene(s, o["hairball_triangles"])],
            "workloads": [{"name": "diffuse", "rays": ["diffuse"], "resolution": o["resolution"]}],
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
                "prefetch_redundant": pf.get("redundant"),
                "hit_mismatches": r["hit_mismatches"],
                "work_mismatches": r["work_mismatches"],
            }
        )
    out.sort(key=lambda x: (SCENES.index(x["scene"]), x["accel"], LABELS.index(x["point"])))
    return out


def _find(rs: list[dict[str, Any]], scene: str, accel: str, point: str) -> dict[str, Any] | None:
    return next(
        (b for b in rs if b["scene"] == scene and b["accel"] == accel and b["point"] == point), None
    )


def _base(rs: list[dict[str, Any]], r: dict[str, Any]) -> dict[str, Any]:
    """The point a row is against: its unit kind's baseline on the same structure."""
    base = "MIMD, same resources" if r["point"].startswith("MIMD") else POINTS[0][0]
    found = _find(rs, r["scene"], r["accel"], base)
    assert found is not None, (r["scene"], r["accel"], base)
    return found


def _memory_share(r: dict[str, Any]) -> float:
    """Memory waits as a share of the cycles of lanes (contexts) with a step to run."""
    working = 1 - sum(r["uses"].get(u, 0.0) for u in IDLE_USES)
    return sum(r["uses"].get(u, 0.0) for u in MEMORY_USES) / working if working > 0 else 0.0


def _note(run: StudyRun) -> str:
    o, m = run.options, run.measured()
    return (
        f"Measured with `{run.command}` (diffuse rays at {o['resolution']}, hairball "
        f"{o['hairball_triangles']:,} triangles, `approx`; rtsim-sim git {m['git']}; "
        f"{m['date']}). One run per point (the model is deterministic); each row against its "
        "unit kind's baseline on the same structure (the warp points against `warp baseline`, "
        "the MIMD ones against `MIMD, same resources`, which is set against the warp "
        "baseline).\n\n"
    )


def table(run: StudyRun) -> str:
    rs = rows(run)
    out = [
        "| scene | structure | config | Mrays/s | vs baseline | BVH B/ray | L1 hit | "
        "DRAM busy | SIMD eff. | prefetched lines/ray | useful | hit mismatches |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rs:
        # The MIMD point is set against the warp baseline, the other MIMD points against it.
        if r["point"] == AQB8_BASE[1]:
            b = _find(rs, r["scene"], r["accel"], POINTS[0][0])
        else:
            b = _base(rs, r)
        speed = r["mrays_per_second"] / b["mrays_per_second"] if b else 0.0
        ratio = "" if b is r or b is None else f"{speed:.2f}x"
        useful = "-" if r["prefetch_useful"] is None else f"{100 * r['prefetch_useful']:.0f}%"
        out.append(
            f"| {r['scene']} | {r['accel']} | {r['point']} | {r['mrays_per_second']:.0f} | "
            f"{ratio} | {r['bvh_bytes_per_ray']:.0f} | {fmt(r['l1_hit_rate'], '.2f')} | "
            f"{100 * r['dram_utilization']:.0f}% | {fmt(r['simd_efficiency'], '.2f')} | "
            f"{fmt(r['prefetch_per_ray'], '.1f')} | {useful} | {r['hit_mismatches']} |"
        )
    return _note(run) + "\n".join(out) + "\n"


def _speed(rs: list[dict[str, Any]], point: str, accel: str = "cwbvh6") -> str:
    cells = []
    for r in rs:
        if r["point"] == point and r["accel"] == accel:
            b = _base(rs, r)
            cell = f"{r['scene']} {r['mrays_per_second'] / b['mrays_per_second']:.2f}x"
            if r["prefetch_useful"] is not None:
                cell += f" ({100 * r['prefetch_useful']:.0f}% of prefetches used)"
            cells.append(cell)
    return ", ".join(cells) or "not run"


def _per_scene(rs: list[dict[str, Any]], point: str, describe: Any) -> str:
    """`describe(row, its baseline)` for the point's cwbvh6 row of each scene."""
    parts = []
    for sc in SCENES:
        r = _find(rs, sc, "cwbvh6", point)
        if r is not None:
            parts.append(f"{sc}: {describe(r, _base(rs, r))}")
    return "; ".join(parts)


def _why_treelet_prefetch(r: dict[str, Any], b: dict[str, Any]) -> str:
    return (
        f"{100 * (r['prefetch_useful'] or 0):.0f}% of prefetched lines used, DRAM "
        f"{100 * b['dram_utilization']:.0f}% -> {100 * r['dram_utilization']:.0f}% busy"
    )


def _why_cooprt(r: dict[str, Any], b: dict[str, Any]) -> str:
    slots, active, helper = (r["lanes"].get(k, 0) for k in ("lane_slots", "active_lanes", "helper"))
    empty = slots - (active - helper)  # lane slots with no ray of their own
    filled = helper / empty if empty else 0.0
    return (
        f"helpers filled {100 * filled:.0f}% of the lane slots without a ray; "
        f"SIMD efficiency {b['simd_efficiency']:.2f} -> {r['simd_efficiency']:.2f}; memory waits "
        f"{100 * _memory_share(b):.0f}% -> {100 * _memory_share(r):.0f}% of working lanes' "
        f"cycles, DRAM {100 * b['dram_utilization']:.0f}% -> "
        f"{100 * r['dram_utilization']:.0f}% busy"
    )


def _why_ttp(r: dict[str, Any], b: dict[str, Any]) -> str:
    cover = (b["l1_misses"] - r["l1_misses"]) / b["l1_misses"] if b["l1_misses"] else 0.0
    sent = r["stack_prefetch"].get("sent", 0)
    present = (r["prefetch_redundant"] or 0) / sent if sent else 0.0
    return (
        f"coverage {100 * cover:.0f}% of L1 misses; {100 * present:.0f}% of the lines it asks "
        f"for are in the L1 already; memory waits are {100 * _memory_share(b):.0f}% of working "
        "lanes' cycles"
    )


def _ratio(r: dict[str, Any], b: dict[str, Any], key: str) -> float:
    return r[key] / b[key] if r.get(key) and b.get(key) else float("nan")


def _aqb8(rs: list[dict[str, Any]], point: str, baseline: str) -> str:
    """AQB8's point on cwbvh6 against the fp32 BVH6 baseline, per scene."""
    parts = []
    for sc in SCENES:
        q, b = _find(rs, sc, "cwbvh6", point), _find(rs, sc, "bvh6", baseline)
        if q is None or b is None:
            continue
        parts.append(
            f"{sc}: DRAM B/ray {_ratio(q, b, 'dram_bytes_per_ray'):.2f}x, energy/ray "
            f"{_ratio(q, b, 'energy_nj'):.2f}x, area {_ratio(q, b, 'area_mm2'):.2f}x, speed "
            f"{_ratio(q, b, 'mrays_per_second'):.2f}x"
        )
    return "; ".join(parts) or "not run"


def papers_row(run: StudyRun) -> str:
    """Each technique on the warp baseline beside its paper, on MIMD units, and why they differ."""
    rs = rows(run)
    out = [
        "| technique | published (Vulkan-Sim) | ours on `vulkansim_rtx2060`, cwbvh6 "
        "| ours on `rtx2060` (MIMD), cwbvh6 | measured on the warp baseline |",
        "|---|---|---|---|---|",
        "| treelet prefetching, no treelet queues (Chou, Nowicki & Aamodt 2023) | +32.1% average | "
        f"{_speed(rs, 'warp + treelet prefetch')} | - (a warp technique) | "
        f"{_per_scene(rs, 'warp + treelet prefetch', _why_treelet_prefetch)} |",
        "| cooperative lanes, `traversal.simt.cooperative` (CoopRT, ISCA 2025) | 2.15x geometric "
        f"mean, up to 5.11x | {_speed(rs, 'warp + CoopRT')} | - (lanes of a warp) | "
        f"{_per_scene(rs, 'warp + CoopRT', _why_cooprt)} |",
        "| stack-driven prefetching, `traversal.stack_prefetch` (TTP, Tozlu, Naithani & Zhou "
        "2026) | 1.48x average, up to 1.89x; 98.92% L1 accuracy, 31.54% coverage | "
        f"{_speed(rs, 'warp + TTP')} | {_speed(rs, 'MIMD + TTP')} | "
        f"{_per_scene(rs, 'warp + TTP', _why_ttp)} |",
        "| quantised box tests, `traversal.quantized_boxes` on cwbvh6, against fp32 bvh6 (AQB8, "
        "Huang, Yang & Yeh, ISCA 2025) | -70% DRAM accesses, -49% energy, -27% area, 1.82x | "
        f"{_aqb8(rs, 'warp + AQB8', 'warp baseline')} | "
        f"{_aqb8(rs, 'MIMD + AQB8', 'MIMD, same resources')} | "
        f"{_per_scene(rs, 'warp + AQB8', _why_aqb8)} |",
    ]
    return _note(run) + "\n".join(out) + "\n"


def _why_aqb8(r: dict[str, Any], b: dict[str, Any]) -> str:
    return (
        f"against dequantised fp32 tests on the same cwbvh6: speed "
        f"{_ratio(r, b, 'mrays_per_second'):.2f}x, energy/ray {_ratio(r, b, 'energy_nj'):.2f}x, "
        f"area {_ratio(r, b, 'area_mm2'):.2f}x"
    )


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
    extra={
        "bvh_bytes_per_ray": bvh_bytes_per_ray,
        "prefetch": prefetch_totals,
        "l1_misses": l1_misses,
        "uses": cycle_uses,
        "stack_prefetch": stack_prefetch_totals,
        "lanes": _lane_totals,
    },
)
