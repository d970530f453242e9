"""Space-partitioning structures against the BVHs (docs/accel.md, "Comparison: space
partitioning against BVHs"): kd-tree, BIH, octree and grid, with and without mailboxes, against
the binary BVH from its three builders (binned SAH, SBVH, LBVH), per scene and ray kind.

- build side, from `rtsim-accel-study` (one thread, median CPU time of `repeats` builds): build
  time, footprint, references per triangle, SAH cost (C_t = C_i = 1 on the cells);
- per ray kind, from each trace's work records: steps (node or cell fetches), box, plane and
  triangle tests, references fetched (mean and p99), and the rays whose hit differs from the
  binary BVH's (the same rays: the workloads trace the scene's own camera);
- on the model at the default config (approx) and again with `mailbox.entries=E` for the
  structures that list references: Mrays/s, DRAM bytes per ray, the triangle tests the mailbox
  skipped and its hit rate;
- build plus trace per frame: each structure's build time plus the time to trace R rays at the
  model's Mrays/s (the mean over the workloads), for R from `frame_rays`, and the rays per frame
  from which each structure beats the binned BVH.

Instanced scenes are traced flattened (the space-partitioning structures have no two-level
form). Tables between the `partition-study` markers of docs/accel.md; the `structures` study is
the same comparison over other structures and rays."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from rtsim.studies._accel_common import (
    REFERENCE,
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
from rtsim.study.traces import manifest

#: Structures whose leaves or cells list references (a mailbox applies).
MAILBOXED = ("kdtree", "octree", "grid")
WORK = ("steps", "box_tests", "plane_tests", "tri_tests", "refs")


def accels(o: dict[str, Any]) -> list[str]:
    """The structures, the binary BVH first (the reference every structure is compared with)."""
    return [REFERENCE, *(a for a in o["accels"] if a != REFERENCE)]


def specs(o: dict[str, Any]) -> list[dict[str, Any]]:
    """Per scene: every structure at the default config, and the mailboxed ones again with
    the mailbox (the binary BVH first: every structure's hits are compared with its)."""
    o = {**o, "accels": accels(o)}
    out = []
    for s in o["scenes"]:
        entry = scene(s, o["hairball_triangles"], flatten=True)
        if o["lights"] != "none":
            entry["lights"] = o["lights"]
        out.append(spec(f"partition-{s}", entry, o))
        boxed = [a for a in o["accels"] if a.partition(":")[0] in MAILBOXED]
        if o["mailbox"] and boxed:
            point = {"label": "mailbox", "set": {"mailbox.entries": o["mailbox"]}}
            out.append(spec(f"partition-{s}-mailbox", entry, {**o, "accels": boxed}, [point]))
    return out


def _model(row: dict[str, Any] | None, timeout: float) -> dict[str, Any]:
    if row is None:
        return {}
    if timed_out(row):
        return {"timed_out": timeout}
    keys = ("mrays_per_second", "dram_bytes_per_ray", "tri_tests_saved_fraction")
    return {k: row[k] for k in keys}


def results(run: StudyRun) -> dict[str, Any]:
    """Per scene: its build figures and, per structure and workload, the work (with the
    trace's references per triangle), hit differences, the model's figures and the mailbox's."""
    o, out = run.options, {}
    for s in o["scenes"]:
        rays: dict[str, Any] = {}
        for r in run.rows(part=f"partition-{s}"):
            boxed = run.rows(
                part=f"partition-{s}-mailbox", workload=r["workload"], accel=r["accel"]
            )
            work = ray_work(run, r, WORK)
            refs = manifest(Path(r["trace_dir"]))["accel"].get("references_per_triangle")
            rays.setdefault(r["accel"], {})[r["workload"]] = {
                "work": work | {"accel": {"references_per_triangle": refs}},
                "model": _model(r, o["sim_timeout"]),
                "mailbox": _model(boxed[0] if boxed else None, o["sim_timeout"]),
                "hits_differ": reference_hits_differ(run, r, f"partition-{s}"),
            }
        out[s] = {"build": build_figures(run, s, accels(o)), "rays": rays}
    return out


def build_table(res: dict[str, Any], o: dict[str, Any]) -> list[str]:
    lines = [
        "| scene | structure | build ms | footprint MiB | vs bvh2 | refs/triangle | SAH cost |",
        "|---|---|---:|---:|---:|---:|---:|",
    ]
    for sc in o["scenes"]:
        st = res[sc]["build"]["structures"]
        ref = st[REFERENCE]["footprint_bytes"]
        for accel in accels(o):
            s = st[accel]
            refs = res[sc]["rays"][accel][o["workloads"][0]]["work"]["accel"].get(
                "references_per_triangle"
            )
            mib = s["footprint_bytes"] / 2**20
            lines.append(
                f"| {sc} | {label(accel)} | {fmt(s['build_ms_cpu'], 0)} | {mib:.2f} | "
                f"{s['footprint_bytes'] / ref:.2f} | {fmt(refs, 2)} | {fmt(s.get('sah_cost'), 1)} |"
            )
    return lines


def ray_table(res: dict[str, Any], o: dict[str, Any]) -> list[str]:
    lines = [
        "| scene | rays | structure | steps | box | plane | tri tests | refs | hits vs bvh2 "
        f"| Mrays/s | DRAM B/ray | mailbox {o['mailbox']}: tri tests saved | Mrays/s "
        "| DRAM B/ray |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for sc in o["scenes"]:
        for workload in o["workloads"]:
            for accel in accels(o):
                r = res[sc]["rays"][accel][workload]
                w, m, mb = r["work"], r["model"], r["mailbox"]
                cells = " | ".join(f"{w[f]['mean']:.1f} / {w[f]['p99']:.0f}" for f in WORK)
                saved = mb.get("tri_tests_saved_fraction")
                saved_text = "-" if saved is None else f"{saved:.1%}"
                lines.append(
                    f"| {sc} | {workload} | {label(accel)} | {cells} | {r['hits_differ']} | "
                    f"{fmt(m.get('mrays_per_second'), 1)} | {fmt(m.get('dram_bytes_per_ray'), 0)} "
                    f"| {saved_text} | {fmt(mb.get('mrays_per_second'), 1)} | "
                    f"{fmt(mb.get('dram_bytes_per_ray'), 0)} |"
                )
    return lines


def beats(build: float, rate: float, base: tuple[float, float]) -> str:
    """From how many rays per frame build + trace is below the binned BVH's."""
    b_build, b_rate = base
    per_ray_gain = 1.0 / (b_rate * 1e3) - 1.0 / (rate * 1e3)  # ms saved per ray
    if build <= b_build and per_ray_gain >= 0:
        return "always"
    if per_ray_gain > 0:
        return f"{(build - b_build) / per_ray_gain / 1e6:.2g} M rays"
    if build < b_build:
        return f"up to {(b_build - build) / -per_ray_gain / 1e6:.2g} M rays"
    return "never"


def frame_table(res: dict[str, Any], o: dict[str, Any]) -> list[str]:
    """Build plus trace per frame: build ms + R / (Mrays/s) ms, and where each beats binned bvh2."""
    frame_rays = o["frame_rays"]
    heads = " | ".join(f"{r / 1e6:g} M rays" for r in frame_rays)
    lines = [
        f"| scene | structure | build ms | Mrays/s | {heads} | beats bvh2 from |",
        "|---|---|---:|---:|" + "---:|" * len(frame_rays) + "---|",
    ]
    for sc in o["scenes"]:
        base = None
        for accel in accels(o):
            build = res[sc]["build"]["structures"][accel]["build_ms_cpu"]
            rates = [
                res[sc]["rays"][accel][w]["model"].get("mrays_per_second") for w in o["workloads"]
            ]
            rate = float(np.mean([x for x in rates if isinstance(x, (int, float))] or [np.nan]))
            if accel == REFERENCE:
                base = (build, rate)
            total = [build + r / (rate * 1e3) for r in frame_rays]
            wins = beats(build, rate, base) if base and accel != REFERENCE else "-"
            lines.append(
                f"| {sc} | {label(accel)} | {build:,.0f} | {rate:.1f} | "
                + " | ".join(f"{t:,.0f}" for t in total)
                + f" | {wins} |"
            )
    return lines


def tables(run: StudyRun) -> str:
    res, o, m = results(run), run.options, run.measured()
    tris = ", ".join(f"{s} {res[s]['build']['triangles']:,}" for s in o["scenes"])
    mailbox = (
        f"then with `mailbox.entries={o['mailbox']}` (kd-tree, octree, grid): the share of "
        "triangle tests it skipped and the model's figures with it"
    )
    lines = [
        f"Measured on {m['host']} on {m['date']} with `{run.command}` (triangles: {tris}). "
        "Build: one thread, median CPU time of the builds, on a machine shared with other "
        "jobs; footprint: every region (nodes, references, triangle records); refs/triangle: "
        "references listed per scene triangle (leaf or cell lists; a BVH's triangle records "
        "per triangle); SAH cost with C_t = C_i = 1 over each structure's cells or boxes (the "
        "grid has none).",
        "",
        *build_table(res, o),
        "",
        "Per ray of each kind (mean / p99) from the reference traversal; *hits vs bvh2*: rays "
        "whose hit (primitive and bits of t) differs from the binary BVH's; model at the "
        f"default config (approx) on the whole trace, {mailbox}. Every simulation replayed "
        "its trace with 0 hit and 0 work mismatches (the study stops otherwise).",
        "",
        *ray_table(res, o),
        "",
        "Build plus trace per frame (ms): build time (host CPU, above) plus R rays at the "
        "model's mean Mrays/s over the workloads; *beats bvh2 from*: the rays per frame from "
        "which the structure's total is below the binned BVH's (its faster tracing pays back "
        "a slower build, or its faster build outweighs slower tracing up to that many rays).",
        "",
        *frame_table(res, o),
    ]
    return "\n".join(lines) + "\n"


#: The documented run's scenes and structures.
SCENES = ["teapot_stadium", "rotated_walls", "aligned_walls", "sponza", "stanford_bunny",
          "hairball", "cornell"]  # fmt: skip
ACCELS = ["bvh2", "bvh2:sbvh", "bvh2:lbvh", "kdtree", "bih", "bih:wachter_keller", "octree", "grid"]

#: The documented run (docs/accel.md, "Comparison: space partitioning against BVHs").
OPTIONS: dict[str, Any] = {
    "scenes": SCENES,
    "accels": ACCELS,
    "workloads": ["primary", "diffuse"],
    "resolution": "64x48",
    "repeats": 3,
    "hairball_triangles": 200_000,
    "mailbox": 8,  # mailbox entries of the second run (0: none)
    "frame_rays": [1e6, 8e6],
    "lights": "none",  # sun: a light added to scenes without any, so shadow rays exist
    "sim_timeout": 1800.0,  # seconds per simulation (then a row without model figures)
}

STUDY = Study(
    name="partition",
    about="kd-tree, BIH, octree and grid (with mailboxes) against the BVH's three builders",
    specs=specs,
    tables=[Table("accel.md", "partition-study", tables)],
    options=OPTIONS,
    quick={
        "scenes": ["cornell"],
        "accels": ["bvh2", "kdtree", "grid"],
        "resolution": "32x24",
        "repeats": 1,
    },
    extra={"tri_tests_saved_fraction": "mailbox.tri_tests_saved_fraction"},
    allow_failed=True,  # a run over sim_timeout is a row without model figures
)
