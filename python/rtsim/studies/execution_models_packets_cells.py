"""Packets on the space-partitioning structures (docs/execution_models.md, "Packets on kd-trees,
BIHs, octrees and grids"): packets of 4 and 16 rays and the hybrid with its split rays on the
packet's free lanes, on the kd-tree (the structure Wald et al. 2001 built packet tracing on), the
BIH, the octree and the uniform grid, each beside single rays (MIMD) on the same structure and
beside MIMD and packets of 16 on the binary BVH; hairball and Sponza, primary, diffuse and shadow
rays. Table between the `execution-models-packets-cells` markers of docs/execution_models.md."""

from __future__ import annotations

from typing import Any

from rtsim.studies.execution_models import CONTEXTS
from rtsim.studies.execution_models_packets import packet_counters, packet_rows, packet_specs
from rtsim.study import Study, StudyRun, Table
from rtsim.study.tables import ByConfig, fmt, mismatches

LANES = {"traversal.packet.split_walks": "lanes"}
CELLS = ["kdtree", "bih", "octree", "grid"]
#: (label, accel, model, lanes, split_below, sort, extra sets)
CELL_CONFIGS: list[tuple[str, str, str, int, float, str, dict[str, Any]]] = [
    ("MIMD", "bvh2", "mimd", 0, 0.0, "none", {}),
    ("packet 16", "bvh2", "packet", 16, 0.0, "none", {}),
]
for _kind in CELLS:
    CELL_CONFIGS += [
        (f"MIMD {_kind}", _kind, "mimd", 0, 0.0, "none", {}),
        (f"packet 4 {_kind}", _kind, "packet", 4, 0.0, "none", {}),
        (f"packet 16 {_kind}", _kind, "packet", 16, 0.0, "none", {}),
        (f"hybrid 16 {_kind}, lanes", _kind, "packet", 16, 0.5, "none", LANES),
    ]


def specs(o: dict[str, Any]) -> list[dict[str, Any]]:
    return packet_specs(o, CELL_CONFIGS, "cells")


def structure_of(config: str) -> str:
    """The structure a configuration's label names (the binary BVH when it names none)."""
    last = config.split(",")[0].split()[-1]
    return last if last in CELLS else "bvh2"


def table(run: StudyRun) -> str:
    rows, m = packet_rows(run, CELL_CONFIGS), run.measured()
    lines = [
        f"Measured {m['date']} on {m['host']} by `{run.command}`: the machine above (8 units x "
        f"{CONTEXTS} ray contexts), approx level; hybrid 16 splits below 0.5 of the packet's "
        "rays, its split rays walking at once on the packet's lanes "
        f"(`traversal.packet.split_walks=lanes`); rtsim-sim git {m['git']}. {len(rows)} runs, "
        f"{mismatches(rows)} hit and work mismatches in all (packet work checked against each "
        "structure's reference packet loop). Speed-up: against MIMD on the binary BVH, same "
        "trace; vs MIMD same: against single rays on the row's own structure.",
        "",
        "| trace | config | Mrays/s | speed-up | vs MIMD same | DRAM B/ray | occupancy | SIMD eff. "
        "| node fetches / packet | split | bottleneck |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|",
    ]
    by = ByConfig(rows)
    for r in rows:
        kind = structure_of(r["config"])
        same = "MIMD" if kind == "bvh2" else f"MIMD {kind}"
        lines.append(
            f"| {r['trace']} | {r['config']} | {r['mrays_per_second']:.1f} | "
            f"{by.against(r):.2f}x | {by.against(r, same):.2f}x | "
            f"{r['dram_bytes_per_ray']:.0f} | {fmt(r['occupancy'], '.1f')} | "
            f"{fmt(r.get('simd_efficiency'), '.2f')} | {fmt(r['fetches'], '.0f')} | "
            f"{fmt(r['splits'], '.2f')} | {r.get('bottleneck') or '-'} |"
        )
    return "\n".join(lines) + "\n"


STUDY = Study(
    name="execution_models_packets_cells",
    about="packets and the hybrid on the kd-tree, BIH, octree and grid beside MIMD on each",
    specs=specs,
    tables=[Table("execution_models.md", "execution-models-packets-cells", table)],
    # The documented run (docs/execution_models.md, measured at 48x36).
    options={
        "scenes": ["hairball", "sponza"],
        "resolution": "48x36",
        "hairball_triangles": 50_000,
        "lights": "sun",  # for the shadow rays
    },
    quick={"scenes": ["hairball"], "resolution": "16x12", "hairball_triangles": 5_000},
    extra={"packet": packet_counters},
)
