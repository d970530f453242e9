"""Execution models (docs/execution_models.md): MIMD units against SIMT warps of 8, 16 and 32
lanes, with and without ray sorting at dispatch, on Cornell, hairball and Sponza, primary,
diffuse and shadow (any-hit) rays, a sun added to the scenes without lights (Sponza and the
hairball), at the approx level (every hit and every ray's work checked).

All runs share one machine: 8 units x 64 ray contexts (MIMD: 64 independent contexts; SIMT:
64 / lanes warps), rays dealt to units 64 at a time (dispatch.block_rays), the default
pipelines, caches and DRAM; only the traversal.model, lanes, SIMT policies and dispatch.sort
change. Tables between the `execution-models`, `execution-models-trends` and
`execution-models-sorting` markers of docs/execution_models.md; figure
docs/execution_models.png (Mrays/s against MIMD and SIMD efficiency per trace)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from rtsim.study import Figure, Study, StudyRun, Table
from rtsim.study.plots import bars_against_mimd
from rtsim.study.tables import ByConfig, fmt, mismatches, scene, units

KINDS = ["primary", "diffuse", "shadow"]
CONTEXTS = 64
BLOCK = 64
#: The sorting table's windows (4,096 is the default) on one larger trace.
SORT_WINDOWS = [4096, 65536]


def machine(model: str, sort: str = "none") -> dict[str, Any]:
    """The sets every run shares, for one unit kind and dispatch sort."""
    return {
        "traversal.model": model,
        "traversal.ray_contexts": CONTEXTS,
        "dispatch.sort": sort,
        "dispatch.block_rays": BLOCK,
    }


def simt(lanes: int, sort: str = "none", policy: str = "while_while", refill: str = "lane"):
    sets = machine("simt", sort)
    sets.update({"traversal.simt.lanes": lanes, "traversal.simt.policy": policy})
    sets["traversal.simt.refill"] = refill
    return sets


def points() -> list[dict[str, Any]]:
    """The configurations, each labelled as the table names it."""
    out = [
        {"label": "MIMD", "set": machine("mimd")},
        {"label": "MIMD + sort", "set": machine("mimd", "origin_direction")},
    ]
    for sort, tag in (("none", ""), ("origin_direction", " + sort")):
        out += [{"label": f"SIMT {n}{tag}", "set": simt(n, sort)} for n in (8, 16, 32)]
    out.append({"label": "SIMT 32 if-if", "set": simt(32, policy="if_if")})
    out.append({"label": "SIMT 32 warp refill", "set": simt(32, refill="warp")})
    return out


def sort_points() -> list[dict[str, Any]]:
    out = []
    for label, base in (("MIMD", machine("mimd")), ("SIMT 32", simt(32))):
        out.append({"label": f"{label}|-", "set": base})
        for window in SORT_WINDOWS:
            # The stage sorts within a chunk: the chunk at least as large as the window.
            sets = {**base, "dispatch.sort": "origin_direction", "dispatch.sort_window": window}
            sets["dispatch.chunk_rays"] = max(16384, window)
            out.append({"label": f"{label} + sort|{window}", "set": sets})
    return out


def specs(o: dict[str, Any]) -> list[dict[str, Any]]:
    """One spec per scene (primary, diffuse and shadow rays, every configuration), and the sorting
    table's Sponza diffuse trace at `sort_resolution`."""
    out = [
        {
            "name": f"execution-models-{s}",
            "scenes": [scene(s, o["hairball_triangles"], lights=o["lights"])],
            "workloads": [{"name": k, "rays": [k], "resolution": o["resolution"]} for k in KINDS],
            "points": points(),
        }
        for s in o["scenes"]
    ]
    if o["sort_study"] and "sponza" in o["scenes"]:
        workload = {"name": "diffuse", "rays": ["diffuse"], "resolution": o["sort_resolution"]}
        out.append(
            {
                "name": "execution-models-sorting",
                "scenes": [{"name": "sponza"}],
                "workloads": [workload],
                "points": sort_points(),
            }
        )
    return out


def coalesced_fraction(rec: Any) -> float | None:
    """Memory requests after coalescing per lane request (SIMT units only)."""
    us = units(rec)
    lanes = sum(u.get("lane_requests", 0) for u in us)
    return sum(u.get("coalesced_requests", 0) for u in us) / lanes if lanes else None


def main_rows(run: StudyRun) -> list[dict[str, Any]]:
    """The main table's rows, each with `trace` (scene_rays) and `config` (its label)."""
    rows = []
    for r in run.rows():
        if r["part"] == "execution-models-sorting":
            continue
        trace = f"{r['part'].removeprefix('execution-models-')}_{r['workload']}"
        rows.append({**r, "trace": trace, "config": r["point"]})
    return rows


def table(run: StudyRun) -> str:
    rows, m = main_rows(run), run.measured()
    lines = [
        f"Measured {m['date']} on {m['host']} by `{run.command}`: one `rtsim-sim` run per row "
        f"at the approx level (deterministic: one run, no medians needed), 8 units x {CONTEXTS} "
        f"ray contexts, `dispatch.block_rays={BLOCK}` (a warp gets neighbouring rays), defaults "
        "otherwise; SIMT while-while with lane refill unless named; sort = "
        f"`dispatch.sort=origin_direction`; rtsim-sim git {m['git']}. {len(rows)} runs, "
        f"{mismatches(rows)} hit and work mismatches in all. Speed-up: Mrays/s against MIMD "
        "without sorting on the same trace.",
        "",
        "| trace | rays | config | Mrays/s | speed-up | DRAM B/ray | nJ/ray | SIMD eff. "
        "| requests after coalescing | L1 hit | bottleneck |",
        "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---|",
    ]
    by = ByConfig(rows)
    for r in rows:
        lines.append(
            f"| {r['trace']} | {r['rays']:,} | {r['config']} | {r['mrays_per_second']:.1f} | "
            f"{by.against(r):.2f}x | {r['dram_bytes_per_ray']:.0f} | "
            f"{fmt(r.get('energy_per_ray_nj'), '.1f')} | {fmt(r.get('simd_efficiency'), '.2f')} "
            f"| {fmt(r['coalesced_fraction'], '.2f')} | {r['l1_hit_rate']:.3f} | "
            f"{r.get('bottleneck') or '-'} |"
        )
    return "\n".join(lines) + "\n"


def trends(run: StudyRun) -> str:
    """Our figures beside the published trends, per scene."""
    by = ByConfig(main_rows(run))
    eff, speed = by.efficiency, by.speed

    def shadow(t: str) -> str:
        if (t, "MIMD") not in by.rows:
            return "-"
        return f"{eff(t, 'SIMT 32')}, {speed(t, 'SIMT 32', 'MIMD')}"

    lines = [
        "| scene | SIMD eff. SIMT 32, primary -> diffuse | SIMT 32 / MIMD, primary -> diffuse "
        "| sorting, MIMD diffuse | sorting, SIMT 32 diffuse | SIMD eff. SIMT 32 diffuse, "
        "sorted | SIMD eff. and SIMT 32 / MIMD, shadow |",
        "|---|---|---|---:|---:|---:|---|",
    ]
    for sc in run.options["scenes"]:
        p, d = f"{sc}_primary", f"{sc}_diffuse"
        if (p, "MIMD") not in by.rows or (d, "MIMD") not in by.rows:
            continue
        lines.append(
            f"| {sc} | {eff(p, 'SIMT 32')} -> {eff(d, 'SIMT 32')} | "
            f"{speed(p, 'SIMT 32', 'MIMD')} -> {speed(d, 'SIMT 32', 'MIMD')} | "
            f"{speed(d, 'MIMD + sort', 'MIMD')} | {speed(d, 'SIMT 32 + sort', 'SIMT 32')} | "
            f"{eff(d, 'SIMT 32 + sort')} | {shadow(f'{sc}_shadow')} |"
        )
    lines.append(
        "| published | Aila & Laine 2009: high on primary rays, falling on diffuse | "
        "SIMT GPUs hide divergence with many more warps per core than here | "
        "Boulos et al. 2008, packet reordering: about 1.5x on diffuse paths | "
        "Meister et al. 2020, sorting: 1.3-2.0x on incoherent rays | | any-hit rays end at "
        "their first hit: shorter, more divergent walks |"
    )
    return "\n".join(lines) + "\n"


def sorting(run: StudyRun) -> str:
    """Sorting on a larger batch (Sponza diffuse): does a bigger window buy coherence?"""
    rows = run.rows(part="execution-models-sorting")
    if not rows:
        return "Not measured in this run (it needs Sponza and `--option sort_study=true`).\n"
    lines = [
        f"Sponza diffuse at {run.options['sort_resolution']}, same machine and method as above; "
        "`dispatch.sort_window` as given (4,096 is the default; `dispatch.chunk_rays` at least "
        "as large, since the stage sorts within a chunk).",
        "",
        "| config | window | rays | Mrays/s | speed-up from sorting | DRAM B/ray | SIMD eff. "
        "| mismatches |",
        "|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    base = {r["point"].split("|")[0]: r for r in rows if r["point"].endswith("|-")}
    for r in rows:
        config, window = r["point"].split("|")
        b = base[config.removesuffix(" + sort")]
        lines.append(
            f"| {config} | {window} | {r['rays']:,} | {r['mrays_per_second']:.1f} | "
            f"{r['mrays_per_second'] / b['mrays_per_second']:.2f}x | "
            f"{r['dram_bytes_per_ray']:.0f} | {fmt(r.get('simd_efficiency'), '.2f')} | "
            f"{mismatches([r])} |"
        )
    return "\n".join(lines) + "\n"


def plot(run: StudyRun, path: Path) -> None:
    bars_against_mimd(
        main_rows(run),
        path,
        "Execution models: throughput against MIMD (8 units x 64 ray contexts)",
        "SIMT: active lanes / lane slots",
    )


STUDY = Study(
    name="execution_models",
    about="MIMD units against SIMT warps of 8-32 lanes, with and without ray sorting",
    specs=specs,
    tables=[
        Table("execution_models.md", "execution-models", table),
        Table("execution_models.md", "execution-models-trends", trends),
        Table("execution_models.md", "execution-models-sorting", sorting),
    ],
    figures=[Figure("execution_models.png", plot)],
    # The documented run (docs/execution_models.md, measured at 96x72).
    options={
        "scenes": ["cornell", "hairball", "sponza"],
        "resolution": "96x72",
        "hairball_triangles": 50_000,
        "sort_study": True,
        "sort_resolution": "256x192",
        "lights": "sun",
    },
    quick={"scenes": ["cornell"], "resolution": "16x12", "sort_study": False},
    extra={"coalesced_fraction": coalesced_fraction},
)
