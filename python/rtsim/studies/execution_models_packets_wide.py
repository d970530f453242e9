"""Packets on wide BVHs (docs/execution_models.md, "Packets on wide BVHs"): packets of 4 and 16
rays and the hybrid on 4- and 8-wide BVHs beside MIMD and packets on the binary BVH, on hairball
and Sponza, primary, diffuse and shadow rays; "box x16": a box pipeline as wide as the packet
(`box.width=16`) for every configuration so marked, single rays included, so neither side has
more box throughput; "lanes": the hybrid's split rays walk at once on the packet's free lanes.
Table between the `execution-models-packets-wide` markers of docs/execution_models.md."""

from __future__ import annotations

from typing import Any

from rtsim.studies.execution_models import CONTEXTS
from rtsim.studies.execution_models_packets import packet_counters, packet_rows, packet_specs
from rtsim.study import Study, StudyRun, Table
from rtsim.study.tables import ByConfig, fmt, mismatches

BOX16 = {"box.width": 16}
LANES = {"traversal.packet.split_walks": "lanes"}
#: (label, accel, model, lanes, split_below, sort, extra sets)
WIDE_CONFIGS: list[tuple[str, str, str, int, float, str, dict[str, Any]]] = [
    ("MIMD", "bvh2", "mimd", 0, 0.0, "none", {}),
    ("MIMD bvh4", "bvh4", "mimd", 0, 0.0, "none", {}),
    ("MIMD bvh8", "bvh8", "mimd", 0, 0.0, "none", {}),
    ("packet 16", "bvh2", "packet", 16, 0.0, "none", {}),
    ("packet 16 bvh4", "bvh4", "packet", 16, 0.0, "none", {}),
    ("packet 16 bvh8", "bvh8", "packet", 16, 0.0, "none", {}),
    ("packet 4 bvh4", "bvh4", "packet", 4, 0.0, "none", {}),
    ("MIMD bvh4, box x16", "bvh4", "mimd", 0, 0.0, "none", BOX16),
    ("packet 16 bvh4, box x16", "bvh4", "packet", 16, 0.0, "none", BOX16),
    ("packet 16 bvh8, box x16", "bvh8", "packet", 16, 0.0, "none", BOX16),
    ("hybrid 16 bvh4", "bvh4", "packet", 16, 0.5, "none", {}),
    ("hybrid 16 bvh4, lanes", "bvh4", "packet", 16, 0.5, "none", LANES),
    ("hybrid 16, lanes", "bvh2", "packet", 16, 0.5, "none", LANES),
]


def specs(o: dict[str, Any]) -> list[dict[str, Any]]:
    return packet_specs(o, WIDE_CONFIGS, "wide")


def table(run: StudyRun) -> str:
    rows, m = packet_rows(run, WIDE_CONFIGS), run.measured()
    lines = [
        f"Measured {m['date']} on {m['host']} by `{run.command}`: the machine above (8 units x "
        f"{CONTEXTS} ray contexts), approx level; box x16: `box.width=16` (a box pipeline as wide "
        "as the packet, every configuration so marked); hybrid splits below 0.5 of the packet's "
        "rays, its split rays walking one after another on the packet's context, or with `lanes` "
        "at once on the packet's lanes (`traversal.packet.split_walks=lanes`); rtsim-sim git "
        f"{m['git']}. {len(rows)} runs, {mismatches(rows)} hit and work mismatches in all (packet "
        "work checked against the reference packet loop of each structure). Speed-up: against "
        "MIMD on the binary BVH, same trace.",
        "",
        "| trace | config | Mrays/s | speed-up | vs packet 16 | DRAM B/ray | occupancy | SIMD eff. "
        "| node fetches / packet | split | box tests/ray | bottleneck |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|",
    ]
    by = ByConfig(rows)
    for r in rows:
        lines.append(
            f"| {r['trace']} | {r['config']} | {r['mrays_per_second']:.1f} | "
            f"{by.against(r):.2f}x | "
            f"{by.against(r, 'packet 16'):.2f}x | {r['dram_bytes_per_ray']:.0f} | "
            f"{fmt(r['occupancy'], '.1f')} | "
            f"{fmt(r.get('simd_efficiency'), '.2f')} | {fmt(r['fetches'], '.0f')} | "
            f"{fmt(r['splits'], '.2f')} | {r['box_per_ray']:.1f} | {r.get('bottleneck') or '-'} |"
        )
    return "\n".join(lines) + "\n"


STUDY = Study(
    name="execution_models_packets_wide",
    about="packets and the hybrid on 4- and 8-wide BVHs beside MIMD and packets on bvh2",
    specs=specs,
    tables=[Table("execution_models.md", "execution-models-packets-wide", table)],
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
