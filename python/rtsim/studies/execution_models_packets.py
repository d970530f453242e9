"""Packets beside MIMD single rays (docs/execution_models.md, "Packets"): packets of 4, 16 and 64
rays (Wald et al. 2001), the hybrid that splits low-occupancy packets into single rays (Benthin et
al. 2012), packets re-formed at dispatch by the sorting stage (Boulos et al. 2008's reordering,
at dispatch), and single rays on a binary and an 8-wide BVH (Wald, Benthin & Boulos 2008), on
Cornell, hairball and Sponza, primary, diffuse and shadow rays, at the approx level (packets'
work checked against the reference packet loop).

The machine of the execution_models study (8 units x 64 ray contexts, rays dealt 64 at a time).
Tables between the `execution-models-packets` and `execution-models-packet-trends` markers of
docs/execution_models.md; figure docs/execution_models_packets.png. The packets on wide BVHs are
the execution_models_packets_wide study."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from rtsim.studies.execution_models import BLOCK, CONTEXTS, KINDS, machine
from rtsim.study import Figure, Study, StudyRun, Table
from rtsim.study.plots import bars_against_mimd
from rtsim.study.tables import ByConfig, fmt, mismatches, scene, units

SORT = "origin_direction"
#: (label, accel, model, lanes, split_below, sort, extra sets)
CONFIGS: list[tuple[str, str, str, int, float, str, dict[str, Any]]] = [
    ("MIMD", "bvh2", "mimd", 0, 0.0, "none", {}),
    ("MIMD bvh8", "bvh8", "mimd", 0, 0.0, "none", {}),
    ("packet 4", "bvh2", "packet", 4, 0.0, "none", {}),
    ("packet 16", "bvh2", "packet", 16, 0.0, "none", {}),
    ("packet 64", "bvh2", "packet", 64, 0.0, "none", {}),
    ("hybrid 16", "bvh2", "packet", 16, 0.5, "none", {}),
    ("hybrid 64", "bvh2", "packet", 64, 0.25, "none", {}),
    ("packet 16 + sort", "bvh2", "packet", 16, 0.0, SORT, {}),
]


def point(config: tuple) -> dict[str, Any]:
    label, _, model, lanes, split, sort, extra = config
    sets = {**machine(model, sort), **extra}
    if lanes:
        sets.update({"traversal.packet.lanes": lanes, "traversal.packet.split_below": split})
    return {"label": label, "set": sets}


def packet_specs(o: dict[str, Any], configs: list[tuple], prefix: str) -> list[dict[str, Any]]:
    """One spec per scene and structure, each with the configurations on that structure."""
    out = []
    for s in o["scenes"]:
        for accel in dict.fromkeys(c[1] for c in configs):
            out.append(
                {
                    "name": f"{prefix}-{s}-{accel}",
                    "scenes": [scene(s, o["hairball_triangles"], lights=o["lights"])],
                    "workloads": [
                        {"name": k, "rays": [k], "resolution": o["resolution"]} for k in KINDS
                    ],
                    "accel": [accel],
                    "points": [point(c) for c in configs if c[1] == accel],
                }
            )
    return out


def specs(o: dict[str, Any]) -> list[dict[str, Any]]:
    return packet_specs(o, CONFIGS, "packets")


def _sum(rec: Any, key: str) -> int:
    return sum(u.get(key, 0) for u in units(rec))


def packet_counters(rec: Any) -> dict[str, Any]:
    """Occupancy (active rays per packet step), node fetches and splits per packet, box and
    triangle tests per ray."""
    model = (rec.stats or {}).get("model") or {}
    rays = int(rec.summary.get("rays") or 1)
    tests = {k: sum(p["tests"] for p in model.get(k, {}).values()) for k in ("box", "triangle")}
    packets = _sum(rec, "packets")
    return {
        "occupancy": _sum(rec, "active_lanes") / max(1, _sum(rec, "packet_steps"))
        if packets
        else None,
        "fetches": _sum(rec, "packet_node_fetches") / packets if packets else None,
        "splits": _sum(rec, "packet_splits") / packets if packets else None,
        "box_per_ray": tests["box"] / rays,
        "tri_per_ray": tests["triangle"] / rays,
    }


def packet_rows(run: StudyRun, configs: list[tuple] = CONFIGS) -> list[dict[str, Any]]:
    """The rows in the order of `configs` per trace, with `trace` (scene_rays) and `config`."""
    order = {c[0]: i for i, c in enumerate(configs)}
    rows = []
    for r in run.rows():
        trace = f"{r['part'].split('-')[1]}_{r['workload']}"  # the part: PREFIX-SCENE-ACCEL
        rows.append({**r, **r["packet"], "trace": trace, "config": r["point"]})
    traces = list(dict.fromkeys(r["trace"] for r in rows))
    return sorted(rows, key=lambda r: (traces.index(r["trace"]), order[r["config"]]))


def table(run: StudyRun) -> str:
    rows, m = packet_rows(run), run.measured()
    lines = [
        f"Measured {m['date']} on {m['host']} by `{run.command}`: one `rtsim-sim` run per row "
        "at the approx level (deterministic), the machine above (8 units x "
        f"{CONTEXTS} ray contexts: {CONTEXTS} // lanes packets per unit, "
        f"`dispatch.block_rays={BLOCK}`), binary BVH unless named; hybrid 16 splits below 0.5 of "
        f"the packet's rays, hybrid 64 below 0.25; sort = `dispatch.sort={SORT}`; rtsim-sim git "
        f"{m['git']}. {len(rows)} runs, {mismatches(rows)} hit and work mismatches in all "
        "(packet work checked against the reference packet loop). Speed-up: against MIMD on the "
        "binary BVH, same trace. Occupancy: active rays per packet step (SIMD eff. = occupancy / "
        "lanes).",
        "",
        "| trace | config | Mrays/s | speed-up | DRAM B/ray | occupancy | SIMD eff. | node fetches "
        "/ packet | split | box tests/ray | tri tests/ray | bottleneck |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|",
    ]
    by = ByConfig(rows)
    for r in rows:
        lines.append(
            f"| {r['trace']} | {r['config']} | {r['mrays_per_second']:.1f} | "
            f"{by.against(r):.2f}x | "
            f"{r['dram_bytes_per_ray']:.0f} | {fmt(r['occupancy'], '.1f')} | "
            f"{fmt(r.get('simd_efficiency'), '.2f')} | {fmt(r['fetches'], '.0f')} | "
            f"{fmt(r['splits'], '.2f')} | {r['box_per_ray']:.1f} | "
            f"{r['tri_per_ray']:.1f} | {r.get('bottleneck') or '-'} |"
        )
    return "\n".join(lines) + "\n"


def trends(run: StudyRun) -> str:
    """Our figures beside the published packet trends, per scene."""
    by = ByConfig(packet_rows(run))
    speed, eff = by.speed, by.efficiency
    lines = [
        "| scene | packet 16 / MIMD, primary -> diffuse | SIMD eff. packet 16, primary -> "
        "diffuse | MIMD bvh8 / packet 16, diffuse | hybrid 16 / packet 16, diffuse | re-formed "
        "(sort) / packet 16, diffuse |",
        "|---|---|---|---:|---:|---:|",
    ]
    for sc in run.options["scenes"]:
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


def plot(run: StudyRun, path: Path) -> None:
    bars_against_mimd(
        packet_rows(run),
        path,
        "Packets against single rays (8 units x 64 ray contexts; MIMD: bvh2)",
        "packets: active rays per packet step / lanes",
    )


#: The documented run (docs/execution_models.md, measured at 96x72).
# A sun is added to the scenes without lights (Sponza, the hairball) for the shadow rays.
OPTIONS = {"scenes": ["cornell", "hairball", "sponza"], "resolution": "96x72",
           "hairball_triangles": 50_000, "lights": "sun"}  # fmt: skip

STUDY = Study(
    name="execution_models_packets",
    about="packets of 4-64 rays, the hybrid and re-formed packets beside MIMD single rays",
    specs=specs,
    tables=[
        Table("execution_models.md", "execution-models-packets", table),
        Table("execution_models.md", "execution-models-packet-trends", trends),
    ],
    figures=[Figure("execution_models_packets.png", plot)],
    options=OPTIONS,
    quick={"scenes": ["cornell"], "resolution": "16x12"},
    extra={"packet": packet_counters},
)
