"""Acceleration structures compared per scene and ray kind (docs/accel.md, "Comparison").

Any registered kind and builder (`rtsim trace --help` lists them), written KIND or KIND:BUILDER:

- build side, from `rtsim-accel-study` (one thread, median of `repeats` builds): build time,
  footprint, structure bytes (every region but the triangle records), node bytes, SAH cost, and
  for the wide kinds the SAH cost of the greedy collapse of the same binary tree;
- per ray kind, from the trace's per-ray work records (one trace per workload, `primary` and
  `diffuse`; the diffuse trace holds the diffuse bounces only): steps (node or cell fetches), box
  tests, triangle tests (mean and p99), hit rate, and the rays whose hit (primitive and bits of
  t) differs from the binary BVH's trace of the same workload;
- on the model at the default config (approx) on the whole trace of the workload: Mrays/s, DRAM
  bytes per ray, L1 and L2 hit rates (a run over `sim_timeout` seconds is a row without them);
- derived: the extra work of each compressed kind over its fp32 twin (same tree: quantisation's
  alone) and of the octant order over front-to-back.

Tables between the `accel-study` markers of docs/accel.md."""

from __future__ import annotations

from typing import Any

from rtsim.studies._accel_common import (
    build_figures,
    fmt,
    label,
    ray_work,
    reference_hits_differ,
    spec,
    timed_out,
)
from rtsim.study import Study, StudyRun, Table
from rtsim.study.tables import scene
from rtsim.study.traces import WORK

#: Same tree, one difference: quantisation (cw vs fp32) or the child order (octant vs distance).
TWINS = {"cwbvh6": "bvh6", "cwbvh8": "bvh8", "bvh8_octant": "bvh8", "cwbvh8_octant": "cwbvh8"}


def specs(o: dict[str, Any]) -> list[dict[str, Any]]:
    return [spec(f"accel-{s}", scene(s, o["hairball_triangles"]), o) for s in o["scenes"]]


def results(run: StudyRun) -> dict[str, Any]:
    """Per scene: its build figures and, per structure and workload, the work, hit
    differences and model figures (`timed_out` when the run was stopped)."""
    out: dict[str, Any] = {}
    for s in run.options["scenes"]:
        rays: dict[str, Any] = {}
        for r in run.rows(part=f"accel-{s}"):
            keys = ("mrays_per_second", "dram_bytes_per_ray", "l1_hit_rate", "l2_hit_rate")
            stopped = timed_out(r)
            model = (
                {"timed_out": run.options["sim_timeout"]} if stopped else {k: r[k] for k in keys}
            )
            rays.setdefault(r["accel"], {})[r["workload"]] = {
                "work": ray_work(run, r, WORK),
                "model": model,
                "hits_differ": reference_hits_differ(run, r, f"accel-{s}"),
            }
        out[s] = {"build": build_figures(run, s, run.options["accels"]), "rays": rays}
    return out


def extra_work(rays: dict[str, Any], workload: str) -> dict[str, dict[str, float]]:
    """Per derived kind: percent more steps/box/triangle tests than its twin."""
    out = {}
    for kind, twin in TWINS.items():
        if kind in rays and twin in rays:
            ours, theirs = rays[kind][workload]["work"], rays[twin][workload]["work"]
            out[kind] = {
                f: 100.0 * (ours[f]["sum"] / theirs[f]["sum"] - 1.0) if theirs[f]["sum"] else 0.0
                for f in WORK
            }
    return out


def build_table(res: dict[str, Any], o: dict[str, Any]) -> list[str]:
    lines = [
        "| scene | structure | build ms | footprint MiB | vs bvh2 | structure MiB | vs bvh2 "
        "| node B | SAH cost | SAH greedy |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for sc in o["scenes"]:
        st = res[sc]["build"]["structures"]
        ref = st.get("bvh2", {})
        for accel in o["accels"]:
            s = st[accel]

            def ratio(key: str, s: dict[str, Any] = s, ref: dict[str, Any] = ref) -> str:
                return f"{s[key] / ref[key]:.2f}" if ref.get(key) else "-"

            lines.append(
                f"| {sc} | {label(accel)} | {fmt(s['build_ms_cpu'], 0)} | "
                f"{s['footprint_bytes'] / 2**20:.2f} | {ratio('footprint_bytes')} | "
                f"{s['structure_bytes'] / 2**20:.2f} | {ratio('structure_bytes')} | "
                f"{fmt(s.get('node_bytes', s.get('cell_bytes')))} | {fmt(s.get('sah_cost'), 1)} | "
                f"{fmt(s.get('sah_cost_greedy'), 1)} |"
            )
    return lines


def ray_table(res: dict[str, Any], o: dict[str, Any]) -> list[str]:
    lines = [
        "| scene | rays | structure | steps | box tests | tri tests | hit rate | hits vs bvh2 "
        "| model Mrays/s | DRAM B/ray | L1 hit | L2 hit |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for sc in o["scenes"]:
        for workload in o["workloads"]:
            for accel in o["accels"]:
                r = res[sc]["rays"][accel][workload]
                w, m = r["work"], r["model"]
                cells = " | ".join(f"{w[f]['mean']:.1f} / {w[f]['p99']:.0f}" for f in WORK)
                if m.get("timed_out"):  # the model ran out of time: say so, not a blank
                    m = {"mrays_per_second": f"> {m['timed_out']:g} s"}
                lines.append(
                    f"| {sc} | {workload} | {label(accel)} | {cells} | {w['hit_rate']:.1%} | "
                    f"{fmt(r['hits_differ'])} | "
                    f"{fmt(m.get('mrays_per_second'), 2)} | {fmt(m.get('dram_bytes_per_ray'), 0)} "
                    f"| {fmt(m.get('l1_hit_rate'), 3)} | {fmt(m.get('l2_hit_rate'), 3)} |"
                )
    return lines


def extra_table(res: dict[str, Any], o: dict[str, Any]) -> list[str]:
    lines = [
        "| scene | rays | structure | vs | steps | box tests | tri tests |",
        "|---|---|---|---|---:|---:|---:|",
    ]
    for sc in o["scenes"]:
        for workload in o["workloads"]:
            for kind, e in extra_work(res[sc]["rays"], workload).items():
                cells = " | ".join(f"{e[f]:+.1f}%" for f in WORK)
                lines.append(f"| {sc} | {workload} | {kind} | {TWINS[kind]} | {cells} |")
    return lines if len(lines) > 2 else []


def tables(run: StudyRun) -> str:
    res, o = results(run), run.options
    tris = {s: res[s]["build"]["triangles"] for s in o["scenes"]}
    lines = [
        f"Measured with `{run.command}` (triangles: "
        + ", ".join(f"{s} {n:,}" for s, n in tris.items())
        + "). Build: one thread, median CPU time of the builds, on a machine shared with "
        "other jobs; structure = every region but the triangle records (nodes; for the grid, "
        "cells and references); node B = the record a step fetches (the grid: a cell).",
        "",
        *build_table(res, o),
        "",
        "Per ray of each kind (mean / p99) from the reference traversal (for the grid a step is "
        "a cell step and every reference fetched is a triangle test); model at the default "
        "config (approx) on the trace of that workload; *hits vs bvh2* counts the rays whose "
        "hit (primitive and bits of t) differs from the binary BVH's"
        + (
            f"; '> {o['sim_timeout']:g} s': the simulation was stopped after that long "
            "(`--option sim_timeout`) and has no model figures."
            if o["sim_timeout"]
            else "."
        ),
        "",
        *ray_table(res, o),
    ]
    extra = extra_table(res, o)
    if extra:
        lines += ["", "Extra work of quantisation and of the octant order, over the twin:", ""]
        lines += extra
    return "\n".join(lines) + "\n"


#: The documented run's structures.
ACCELS = ["bvh2", "bvh2:sbvh", "bvh4", "bvh6", "bvh8", "cwbvh6", "cwbvh8", "bvh8_octant",
          "cwbvh8_octant", "grid"]  # fmt: skip

STUDY = Study(
    name="accel",
    about="acceleration structures: build, footprint, SAH, per-ray work and the model per ray kind",
    specs=specs,
    tables=[Table("accel.md", "accel-study", tables)],
    # The documented run (docs/accel.md, "Comparison").
    options={
        "scenes": ["sponza", "bunny", "hairball", "teapot_stadium", "rotated_walls", "cornell"],
        "accels": ACCELS,
        "workloads": ["primary", "diffuse"],
        "resolution": "96x72",
        "repeats": 3,
        "hairball_triangles": 200_000,
        "sim_timeout": 0.0,  # seconds per simulation; 0: the sweep's limit
    },
    quick={
        "scenes": ["cornell"],
        "accels": ["bvh2", "bvh8", "cwbvh8"],
        "resolution": "32x24",
        "repeats": 1,
    },
    allow_failed=True,  # a run over sim_timeout is a row without model figures
)
