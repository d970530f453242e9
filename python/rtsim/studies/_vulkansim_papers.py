"""The papers' rows on the warp baseline (docs/papers.md, "On the paper's own kind of machine"):
each technique the `vulkansim_baseline` study runs, set beside its paper's headline figure, on
`vulkansim_rtx2060` and on MIMD units with the same resources, with the factors measured on the
warp baseline that explain the difference. Functions of the study's rows
(vulkansim_baseline.rows)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from rtsim.study import StudyRun

Row = dict[str, Any]

WARP = "warp baseline"
MIMD = "MIMD, same resources"
#: The sampling comparison's points, on a larger trace of their own (vulkansim_baseline.specs).
SAMPLING_FULL = "warp baseline, sampling's trace"
SAMPLED = "warp, 10% sampled"
#: The study's scenes (vulkansim_baseline.specs), in table order.
SCENES = ["sponza", "hairball"]
#: Context-cycle uses that wait on the memory hierarchy (docs/stats.md, cycle accounting).
MEMORY_USES = ("l1_hit", "l1_mshr_full", "l2", "l2_mshr_full", "dram", "stack")
#: Uses of lanes with nothing to step: waiting for their warp, for rays, or after the last.
IDLE_USES = ("idle_lane", "starved", "tail")


def find(rs: list[Row], scene: str, accel: str, point: str) -> Row | None:
    return next(
        (b for b in rs if b["scene"] == scene and b["accel"] == accel and b["point"] == point), None
    )


def base(rs: list[Row], r: Row) -> Row:
    """The point a row is against: its unit kind's baseline on the same structure."""
    label = MIMD if r["point"].startswith("MIMD") else WARP
    found = find(rs, r["scene"], r["accel"], label)
    assert found is not None, (r["scene"], r["accel"], label)
    return found


def note(run: StudyRun) -> str:
    o, m = run.options, run.measured()
    return (
        f"Measured with `{run.command}` (diffuse rays at {o['resolution']}, hairball "
        f"{o['hairball_triangles']:,} triangles, `{o['fidelity']}`; rtsim-sim git {m['git']}; "
        f"{m['date']}). One run per point (the model is deterministic); each row against its "
        "unit kind's baseline on the same structure (the warp points against `warp baseline`, "
        "the MIMD ones against `MIMD, same resources`, which is set against the warp "
        "baseline).\n\n"
    )


def _memory_share(r: Row) -> float:
    """Memory waits as a share of the cycles of lanes (contexts) with a step to run."""
    working = 1 - sum(r["uses"].get(u, 0.0) for u in IDLE_USES)
    return sum(r["uses"].get(u, 0.0) for u in MEMORY_USES) / working if working > 0 else 0.0


def _ratio(r: Row, b: Row, key: str) -> float:
    return r[key] / b[key] if r.get(key) and b.get(key) else float("nan")


def _speed(rs: list[Row], point: str, accel: str = "cwbvh6") -> str:
    """The point's speed over its baseline on `accel`, per scene (prefetches used, if any)."""
    cells = []
    for r in rs:
        if r["point"] == point and r["accel"] == accel:
            cell = f"{r['scene']} {_ratio(r, base(rs, r), 'mrays_per_second'):.2f}x"
            if r["prefetch_useful"] is not None:
                cell += f" ({100 * r['prefetch_useful']:.0f}% of prefetches used)"
            cells.append(cell)
    return ", ".join(cells) or "not run"


def _against(rs: list[Row], point: str, accel: str, of: str, of_accel: str, say: Callable) -> str:
    """`say(row, against)` per scene for `point` on `accel` against `of` on `of_accel`."""
    parts = []
    for sc in SCENES:
        r, b = find(rs, sc, accel, point), find(rs, sc, of_accel, of)
        if r is not None and b is not None:
            parts.append(f"{sc}: {say(r, b)}")
    return "; ".join(parts) or "not run"


def _per_scene(rs: list[Row], point: str, say: Callable) -> str:
    """`say(row, its baseline)` for the point's cwbvh6 row of each scene."""
    label = MIMD if point.startswith("MIMD") else SAMPLING_FULL if point == SAMPLED else WARP
    return _against(rs, point, "cwbvh6", label, "cwbvh6", say)


def _why_treelet_prefetch(r: Row, b: Row) -> str:
    return (
        f"{100 * (r['prefetch_useful'] or 0):.0f}% of prefetched lines used, DRAM "
        f"{100 * b['dram_utilization']:.0f}% -> {100 * r['dram_utilization']:.0f}% busy"
    )


def _why_cooprt(r: Row, b: Row) -> str:
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


def _why_ttp(r: Row, b: Row) -> str:
    cover = (b["l1_misses"] - r["l1_misses"]) / b["l1_misses"] if b["l1_misses"] else 0.0
    sent = r["stack_prefetch"].get("sent", 0)
    present = (r["prefetch_redundant"] or 0) / sent if sent else 0.0
    return (
        f"coverage {100 * cover:.0f}% of L1 misses; {100 * present:.0f}% of the lines it asks "
        f"for are in the L1 already; memory waits are {100 * _memory_share(b):.0f}% of working "
        "lanes' cycles"
    )


def _aqb8_totals(r: Row, b: Row) -> str:
    return (
        f"DRAM B/ray {_ratio(r, b, 'dram_bytes_per_ray'):.2f}x, energy/ray "
        f"{_ratio(r, b, 'energy_nj'):.2f}x, area {_ratio(r, b, 'area_mm2'):.2f}x, speed "
        f"{_ratio(r, b, 'mrays_per_second'):.2f}x"
    )


def _why_aqb8(r: Row, b: Row) -> str:
    return (
        f"against dequantised fp32 tests on the same cwbvh6: speed "
        f"{_ratio(r, b, 'mrays_per_second'):.2f}x, energy/ray {_ratio(r, b, 'energy_nj'):.2f}x, "
        f"area {_ratio(r, b, 'area_mm2'):.2f}x; {100 * (r['extra_steps'] or 0):.0f}% more node "
        "steps"
    )


def _speed_only(r: Row, b: Row) -> str:
    return f"{_ratio(r, b, 'mrays_per_second'):.2f}x"


def _why_ylitie(r: Row, b: Row) -> str:
    return (
        f"DRAM B/ray {_ratio(r, b, 'dram_bytes_per_ray'):.2f}x, SIMD efficiency "
        f"{b['simd_efficiency']:.2f} -> {r['simd_efficiency']:.2f}"
    )


def _traffic(r: Row, b: Row) -> str:
    return (
        f"all DRAM B/ray {100 * (_ratio(r, b, 'dram_bytes_per_ray') - 1):+.0f}%, BVH "
        f"{100 * (_ratio(r, b, 'bvh_bytes_per_ray') - 1):+.0f}%, speed "
        f"{_ratio(r, b, 'mrays_per_second'):.2f}x"
    )


def _why_treelets(r: Row, b: Row) -> str:
    return (
        f"SIMD efficiency {b['simd_efficiency']:.2f} -> {r['simd_efficiency']:.2f} (warps form "
        f"from one queue's few rays), L1 hit {b['l1_hit_rate']:.2f} -> {r['l1_hit_rate']:.2f}"
    )


def _short_stack(r: Row, b: Row) -> str:
    return (
        f"+{100 * (r['restart_steps'] or 0):.1f}% node steps from restarts, speed "
        f"{_ratio(r, b, 'mrays_per_second'):.2f}x"
    )


def _why_short_stack(r: Row, b: Row) -> str:
    return f"{r['restarts'] or 0:.2f} restarts per ray"


def _reduced_boxes(r: Row, b: Row) -> str:
    return (
        f"+{100 * (r['extra_steps'] or 0):.1f}% node steps, DRAM B/ray "
        f"{_ratio(r, b, 'dram_bytes_per_ray'):.2f}x, speed "
        f"{_ratio(r, b, 'mrays_per_second'):.2f}x, energy/ray {_ratio(r, b, 'energy_nj'):.2f}x, "
        f"area {_ratio(r, b, 'area_mm2'):.2f}x"
    )


def _leaves(r: Row, b: Row) -> str:
    return (
        f"DRAM B/ray {_ratio(r, b, 'dram_bytes_per_ray'):.2f}x, speed "
        f"{_ratio(r, b, 'mrays_per_second'):.2f}x"
    )


def _why_sorting(r: Row, b: Row) -> str:
    return (
        f"SIMD efficiency {b['simd_efficiency']:.2f} -> {r['simd_efficiency']:.2f}, L1 hit "
        f"{b['l1_hit_rate']:.2f} -> {r['l1_hit_rate']:.2f}, DRAM B/ray "
        f"{_ratio(r, b, 'dram_bytes_per_ray'):.2f}x"
    )


def _sampling(r: Row, b: Row) -> str:
    error = _ratio(r, b, "mrays_per_second") - 1
    wall = b["wall_seconds"] / r["wall_seconds"] if r.get("wall_seconds") else float("nan")
    return f"{100 * error:+.1f}% Mrays/s error at {wall:.1f}x less wall time"


def papers_rows(run: StudyRun, rs: list[Row]) -> str:
    """Each technique on the warp baseline beside its paper, on MIMD units, and why they differ."""
    row = " | ".join
    lines = [
        "| technique | published (on a GPU or Vulkan-Sim) | ours on `vulkansim_rtx2060` "
        "| ours on `rtx2060` (MIMD) | measured on the warp baseline |",
        "|---|---|---|---|---|",
    ]

    def add(*cells: str) -> None:
        lines.append("| " + row(cells) + " |")

    add(
        "compressed 8-wide BVH, cwbvh8 against bvh2 (Ylitie, Karras & Laine 2017)",
        "1.9-2.1x on incoherent rays (a GPU, software traversal)",
        _against(rs, WARP, "cwbvh8", WARP, "bvh2", _speed_only),
        _against(rs, MIMD, "cwbvh8", MIMD, "bvh2", _speed_only),
        _against(rs, WARP, "cwbvh8", WARP, "bvh2", _why_ylitie),
    )
    add(
        "treelet ray queues, `treelets.enabled` (Aila & Karras 2010), cwbvh6",
        "up to 90% less total memory traffic in difficult scenes",
        _per_scene(rs, "warp + treelets", _traffic),
        "the table above (MIMD default)",
        _per_scene(rs, "warp + treelets", _why_treelets),
    )
    add(
        "treelet prefetching, no treelet queues (Chou, Nowicki & Aamodt 2023), cwbvh6",
        "+32.1% average",
        _speed(rs, "warp + treelet prefetch"),
        "- (a warp technique)",
        _per_scene(rs, "warp + treelet prefetch", _why_treelet_prefetch),
    )
    add(
        "short stack with a restart trail, 5 entries (Vaidyanathan, Woop & Benthin 2019), cwbvh6",
        "traversal steps with 5 entries close to a full stack's",
        _per_scene(rs, "warp + short stack", _short_stack),
        "the table above (MIMD default)",
        _per_scene(rs, "warp + short stack", _why_short_stack),
    )
    add(
        "short stack with a restart trail, 5 entries, binary BVH (Laine 2010), bvh2",
        "restarts make a short stack possible (measured against a full stack on GPUs)",
        _against(rs, "warp + short stack", "bvh2", WARP, "bvh2", _short_stack),
        "the table above (MIMD default)",
        _against(rs, "warp + short stack", "bvh2", WARP, "bvh2", _why_short_stack),
    )
    add(
        "reduced-precision box tests, 8 bits (Keely 2014), cwbvh6",
        "compact traversal hardware for little extra traversal (simulated GPU)",
        _per_scene(rs, "warp + 8-bit boxes", _reduced_boxes),
        "the table above (MIMD default)",
        "on bvh2: " + _against(rs, "warp + 8-bit boxes", "bvh2", WARP, "bvh2", _reduced_boxes),
    )
    add(
        "compressed leaves under cwbvh6 (Benthin, Wald, Woop & Afra 2018)",
        "about the memory savings of Embree's compressed BVH, almost the speed of its fastest",
        _against(rs, WARP, "cwbvh6+leaves", WARP, "cwbvh6", _leaves),
        _against(rs, MIMD, "cwbvh6+leaves", MIMD, "cwbvh6", _leaves),
        "Embree's figures are a CPU's; an RT unit's are the two columns",
    )
    add(
        "ray sorting, `dispatch.sort=origin_direction`, window 65,536 (Meister et al. 2020), "
        "cwbvh6",
        "1.3-2.0x on incoherent rays",
        _speed(rs, "warp + ray sorting"),
        _speed(rs, "MIMD + ray sorting"),
        _per_scene(rs, "warp + ray sorting", _why_sorting),
    )
    add(
        "cooperative lanes, `traversal.simt.cooperative` (CoopRT, ISCA 2025), cwbvh6",
        "2.15x geometric mean, up to 5.11x",
        _speed(rs, "warp + CoopRT"),
        "- (lanes of a warp)",
        _per_scene(rs, "warp + CoopRT", _why_cooprt),
    )
    add(
        "stack-driven prefetching, `traversal.stack_prefetch` (TTP, Tozlu, Naithani & Zhou "
        "2026), cwbvh6",
        "1.48x average, up to 1.89x; 98.92% L1 accuracy, 31.54% coverage",
        _speed(rs, "warp + TTP"),
        _speed(rs, "MIMD + TTP"),
        _per_scene(rs, "warp + TTP", _why_ttp),
    )
    add(
        "quantised box tests, `traversal.quantized_boxes` on cwbvh6, against fp32 bvh6 (AQB8, "
        "Huang, Yang & Yeh, ISCA 2025)",
        "-70% DRAM accesses, -49% energy, -27% area, 1.82x",
        _against(rs, "warp + AQB8", "cwbvh6", WARP, "bvh6", _aqb8_totals),
        _against(rs, "MIMD + AQB8", "cwbvh6", MIMD, "bvh6", _aqb8_totals),
        _per_scene(rs, "warp + AQB8", _why_aqb8),
    )
    add(
        "sampling, `sampling.fraction=0.1`, cwbvh6 (against Zatel, ISPASS 2024)",
        "<1% cycle error at 10x speed-up (Vulkan-Sim)",
        _per_scene(rs, SAMPLED, _sampling),
        "- (the sampling rows of docs/fidelity.md)",
        "the sample's trace is larger (the `sampling_resolution` option), so its clusters hold "
        "their warm-up; wall time is this machine's, one run each",
    )
    return note(run) + "\n".join(lines) + "\n"
