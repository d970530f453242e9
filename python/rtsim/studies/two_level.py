"""Flattened against two-level structures on instanced scenes (docs/accel.md, "Two-level
structures", the comparison table).

For every scene, BLAS kind and mode (`flatten: true`, or the default two levels), one trace of
the workload the scene calls for (one bounce) and one `rtsim-sim` run at the default config:

- from the trace: the image's footprint, triangles placed, and per ray the node steps (TLAS and
  BLAS fetches of nodes), transforms and triangle tests;
- the tracer made again `repeat` times under `/usr/bin/time -v` (a measurement of the study, not
  a run): the median build time and the tracer's peak memory;
- from the run: Mrays/s, DRAM bytes per ray, the hit and work mismatches (0, or the study
  stops) and rtsim-sim's own peak memory.

A mode that cannot run (the forest cannot be flattened on this machine) is a row with the reason
its trace failed. Table between the `two-level-study` markers of docs/accel.md."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from rtsim.study import Study, StudyRun, Table
from rtsim.study.tables import fmt
from rtsim.study.traces import manifest, retrace, work_stats

MODES = (("flattened", True), ("two-level", False))


def specs(o: dict[str, Any]) -> list[dict[str, Any]]:
    workload = {"name": "scene", "resolution": o["resolution"], "bounces": 1}
    return [
        {
            "name": f"two-level-{s}-{mode}",
            "scenes": [{"name": s, "flatten": True} if flat else {"name": s}],
            "workloads": [workload],
            "accel": list(o["accels"]),
        }
        for s in o["scenes"]
        for mode, flat in MODES
    ]


def short_error(text: str) -> str:
    """The part of a failed trace's message that says why (e.g. "flattens to N triangles")."""
    match = re.search(r"flattens to (\d+) triangles \(about ([0-9.]+ GiB)", text)
    if match:
        return f"flattens to {int(match.group(1)):,} triangles, about {match.group(2)} to trace"
    lines = (
        [s for s in text.splitlines() if "error" in s.lower()] or text.splitlines() or ["failed"]
    )
    return lines[-1][:200]


def measure(run: StudyRun, r: dict[str, Any]) -> dict[str, Any]:
    """One row's figures: the trace's, the re-made traces' and the run's."""
    folder = Path(r["trace_dir"])
    if not (folder / "manifest.json").is_file():  # the trace itself failed
        return {"error": short_error(str(r.get("error") or ""))}
    m = manifest(folder)
    work = run.cached(
        f"work-{folder.name}-all-rays",
        lambda: work_stats(folder, None, ("steps", "transforms", "tri_tests")),
    )
    timing = run.cached(
        f"retrace-{folder.name}-{run.options['repeat']}",
        lambda: retrace(folder, run.options["repeat"]),
    )
    rays = max(work["rays"], 1)
    row: dict[str, Any] = {
        "footprint_mib": m["accel"]["footprint_bytes"] / 2**20,
        "build_ms": timing["build_ms"],
        "trace_peak_mib": timing["peak_mib"],
        "triangles": m["scene"]["triangles"],
        "steps_per_ray": work["steps"]["sum"] / rays,
        "transforms_per_ray": work["transforms"]["sum"] / rays,
        "tri_tests_per_ray": work["tri_tests"]["sum"] / rays,
    }
    if r["status"] == "ok":
        row.update(
            mrays_per_second=r["mrays_per_second"],
            dram_bytes_per_ray=r["dram_bytes_per_ray"],
            mismatches=r["hit_mismatches"] + r["work_mismatches"],
            sim_peak_mib=r["peak_memory_mib"],
        )
    return row


def table(run: StudyRun) -> str:
    head = (
        f"Measured with `{run.command}`: build time is the median of the traces' builds, "
        "trace peak memory the tracer's largest resident set (`/usr/bin/time -v`), sim peak "
        "rtsim-sim's own (its `peak_memory_mib`); Mrays/s and DRAM bytes per ray are the model's "
        "at the default configuration. The machine was shared with other jobs.\n\n"
        "| scene | accel | mode | triangles placed | footprint MiB | build ms | trace peak MiB "
        "| steps/ray | transforms/ray | tri tests/ray | Mrays/s | DRAM B/ray | sim peak MiB "
        "| mismatches |\n|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n"
    )
    lines = []
    for s in run.options["scenes"]:
        for kind in run.options["accels"]:
            for mode, _ in MODES:
                r = measure(run, run.row(part=f"two-level-{s}-{mode}", accel=kind))
                lead = f"| {s} | {kind} | {mode} |"
                if "error" in r:
                    lines.append(f"{lead} - | does not run: {r['error']} |" + " |" * 9)
                    continue
                lines.append(
                    f"{lead} {r['triangles']:,} | {fmt(r.get('footprint_mib'), '.1f')} | "
                    f"{fmt(r.get('build_ms'), ',.0f')} | {fmt(r.get('trace_peak_mib'), ',.0f')} | "
                    f"{fmt(r.get('steps_per_ray'), '.1f')} | "
                    f"{fmt(r.get('transforms_per_ray'), '.2f')} | "
                    f"{fmt(r.get('tri_tests_per_ray'), '.1f')} | "
                    f"{fmt(r.get('mrays_per_second'), '.1f')} | "
                    f"{fmt(r.get('dram_bytes_per_ray'), '.0f')} | "
                    f"{fmt(r.get('sim_peak_mib'), ',.0f')} | {fmt(r.get('mismatches'), 'd')} |"
                )
    return head + "\n".join(lines) + "\n"


STUDY = Study(
    name="two_level",
    about="instanced scenes flattened against two levels: footprint, build, memory, speed",
    specs=specs,
    tables=[Table("accel.md", "two-level-study", table)],
    # The documented run (docs/accel.md): the forest's flattened mode fails by design.
    options={
        "scenes": ["MetalRoughSpheresNoTextures", "SimpleInstancing", "grove", "forest"],
        "accels": ["bvh2", "bvh8"],
        "resolution": "64x48",
        "repeat": 3,
    },
    # No forest: its two-level trace alone is minutes and gigabytes.
    quick={"scenes": ["SimpleInstancing", "grove"], "resolution": "16x12", "repeat": 1},
    allow_failed=True,  # a mode that cannot run is a row saying why
)
