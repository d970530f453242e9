"""Treelets on every unit kind that takes them (docs/treelets.md, docs/execution_models.md):
MIMD units and SIMT warps on diffuse rays of Sponza and a procedural hairball, each without
treelets, with treelet scheduling (the default 512 KiB ray buffer and 2 MiB), with treelet
prefetching into the L1, and with prefetching alone (no treelet queues: a ray stepping into a
treelet triggers its prefetch). The SIMT rows are the warp-based RT unit with treelets that
Chou, Nowicki & Aamodt (MICRO 2023) study on Vulkan-Sim. Table between the `unit-treelets`
markers of docs/treelets.md, its summary between the `execution-models-treelets` markers of
docs/execution_models.md; figure docs/unit_treelets.png."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from rtsim.study import Figure, Study, StudyRun, Table
from rtsim.study.tables import bvh_bytes_per_ray, change, fmt, prefetch_totals, ray_buffer, scene

SCENES = ["sponza", "hairball"]
MODELS = {"mimd": "MIMD", "simt": "SIMT"}

#: (name, what it sets beside traversal.model); the first is each unit kind's baseline.
CONFIGS: list[tuple[str, dict[str, Any]]] = [
    ("baseline", {}),
    ("treelets", {"treelets.enabled": True}),
    ("treelets, buffer 2 MiB", {"treelets.enabled": True, "treelets.buffer_kib": 2048}),
    ("treelets + prefetch", {"treelets.enabled": True, "treelets.prefetch": True}),
    ("prefetch, no queues", {"treelets.prefetch": True}),
    (
        "treelets + prefetch into L2",
        {"treelets.enabled": True, "treelets.prefetch": True, "treelets.prefetch_into": "l2"},
    ),
    ("prefetch into L2, no queues", {"treelets.prefetch": True, "treelets.prefetch_into": "l2"}),
]
QUICK = ["baseline", "treelets", "prefetch, no queues"]


def _label(model: str, config: str) -> str:
    return f"{model}: {config}"


def specs(o: dict[str, Any]) -> list[dict[str, Any]]:
    """One spec per scene: every unit kind with every config on its diffuse rays."""
    configs = [c for c in CONFIGS if not o["short"] or c[0] in QUICK]
    points = [
        {"label": _label(m, name), "set": {"traversal.model": m, **sets}}
        for m in MODELS
        for name, sets in configs
    ]
    return [
        {
            "name": f"unit-treelets-{s}",
            "scenes": [scene(s, o["hairball_triangles"])],
            "workloads": [{"name": "diffuse", "rays": ["diffuse"], "resolution": o["resolution"]}],
            "points": points,
        }
        for s in SCENES
    ]


def rows(run: StudyRun) -> list[dict[str, Any]]:
    out = []
    for r in run.rows():
        model, config = r["point"].split(": ", 1)
        rays = r["rays"]
        pf = r["prefetch"]
        out.append(
            {
                "scene": r["scene"],
                "model": model,
                "config": config,
                "treelets": bool(r["treelets.enabled"]),
                "rays": rays,
                "mrays_per_second": r["mrays_per_second"],
                "dram_bytes_per_ray": r["dram_bytes_per_ray"],
                "bvh_bytes_per_ray": r["bvh_bytes_per_ray"],
                "dram_utilization": r["dram_bandwidth_utilization"],
                "simd_efficiency": r.get("simd_efficiency"),
                "queue_at_pick": r["queue_at_pick"],
                "parks_per_ray": (r["parked"] or 0) / rays if r["treelets.enabled"] else None,
                "prefetch_per_ray": pf["issued"] / rays if pf.get("issued") else None,
                "prefetch_useful": pf["useful"] / pf["issued"] if pf.get("issued") else None,
                "hit_mismatches": r["hit_mismatches"],
            }
        )
    return out


def _base(rs: list[dict[str, Any]], r: dict[str, Any]) -> dict[str, Any]:
    return next(
        b
        for b in rs
        if b["scene"] == r["scene"] and b["model"] == r["model"] and b["config"] == "baseline"
    )


def _note(run: StudyRun) -> str:
    o, m = run.options, run.measured()
    return (
        f"Measured with `{run.command}` (diffuse rays at {o['resolution']}, hairball "
        f"{o['hairball_triangles']:,} triangles, the default accelerator otherwise: 8 units, "
        "16 ray contexts each (a SIMT unit: two warps of 8 lanes), 16 KiB L1s, 1 MiB L2, 16 KiB "
        f"treelets; rtsim-sim git {m['git']}; {m['date']}). One run per point (the model is "
        "deterministic); each row against its own unit kind's baseline.\n\n"
    )


def table(run: StudyRun) -> str:
    rs = rows(run)
    out = [
        "| scene | unit | config | Mrays/s | vs its baseline | BVH B/ray | vs its baseline | "
        "DRAM busy | SIMD eff. | queue at pick | parks/ray | prefetched lines/ray | "
        "useful | hit mismatches |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rs:
        b = _base(rs, r)
        same = b is r
        out.append(
            f"| {r['scene']} | {MODELS[r['model']]} | {r['config']} | "
            f"{r['mrays_per_second']:.1f} | "
            + ("" if same else f"{r['mrays_per_second'] / b['mrays_per_second']:.2f}x")
            + f" | {r['bvh_bytes_per_ray']:.0f} | "
            + ("" if same else change(r["bvh_bytes_per_ray"], b["bvh_bytes_per_ray"]))
            + f" | {100 * r['dram_utilization']:.0f}% | {fmt(r['simd_efficiency'], '.2f')} | "
            f"{fmt(r['queue_at_pick'], '.0f')} | {fmt(r['parks_per_ray'], '.1f')} | "
            f"{fmt(r['prefetch_per_ray'], '.1f')} | "
            + (f"{100 * r['prefetch_useful']:.0f}%" if r["prefetch_useful"] is not None else "-")
            + f" | {r['hit_mismatches']} |"
        )
    return _note(run) + "\n".join(out) + "\n"


def summary(run: StudyRun) -> str:
    """Per scene and unit kind: what treelets, prefetching and both do to throughput."""
    rs = rows(run)
    want = ["treelets", "treelets + prefetch", "prefetch, no queues", "prefetch into L2, no queues"]
    present = [c for c in want if any(r["config"] == c for r in rs)]
    out = [
        "| scene | unit | baseline Mrays/s | "
        + " | ".join(f"{c} / baseline" for c in present)
        + " |",
        "|---|---|---:|" + "---:|" * len(present),
    ]
    for s in SCENES:
        for m in MODELS:
            group = {r["config"]: r for r in rs if r["scene"] == s and r["model"] == m}
            if "baseline" not in group:
                continue
            b = group["baseline"]
            cells = [
                f"{group[c]['mrays_per_second'] / b['mrays_per_second']:.2f}x"
                if c in group
                else "-"
                for c in present
            ]
            out.append(
                f"| {s} | {MODELS[m]} | {b['mrays_per_second']:.1f} | " + " | ".join(cells) + " |"
            )
    return _note(run) + "\n".join(out) + "\n"


def plot(run: StudyRun, path: Path) -> None:
    from rtsim.study.tables import pyplot

    rs = rows(run)
    plt = pyplot()
    configs = [c for c, _ in CONFIGS if any(r["config"] == c for r in rs)]
    colors = {"mimd": "#1f77b4", "simt": "#d62728"}
    fig, axes = plt.subplots(len(SCENES), 2, figsize=(12, 3.8 * len(SCENES)), squeeze=False)
    width = 0.38
    for (ax_speed, ax_bvh), sc in zip(axes, SCENES, strict=True):
        for i, (m, color) in enumerate(colors.items()):
            group = {r["config"]: r for r in rs if r["scene"] == sc and r["model"] == m}
            xs = [j + (i - 0.5) * width for j in range(len(configs))]
            for ax, key in ((ax_speed, "mrays_per_second"), (ax_bvh, "bvh_bytes_per_ray")):
                ax.bar(
                    xs,
                    [group[c][key] if c in group else 0 for c in configs],
                    width,
                    color=color,
                    label=MODELS[m],
                )
        ax_speed.set_title(f"{sc}: throughput at 1 GHz (diffuse rays)", fontsize=10)
        ax_speed.set_ylabel("Mrays/s")
        ax_bvh.set_title(f"{sc}: BVH bytes read from DRAM per ray", fontsize=10)
        ax_bvh.set_ylabel("B/ray")
        for ax in (ax_speed, ax_bvh):
            ax.set_xticks(range(len(configs)), configs, rotation=25, ha="right", fontsize=8)
            ax.grid(True, axis="y", alpha=0.3)
            ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    fig.suptitle("Treelet scheduling and prefetching on MIMD units and SIMT warps", fontsize=12)
    fig.tight_layout(rect=(0, 0, 1, 0.96))
    fig.savefig(path, dpi=80)
    plt.close(fig)


STUDY = Study(
    name="unit_treelets",
    about="treelet scheduling and prefetching on MIMD units and SIMT warps",
    specs=specs,
    tables=[
        Table("treelets.md", "unit-treelets", table),
        Table("execution_models.md", "execution-models-treelets", summary),
    ],
    figures=[Figure("unit_treelets.png", plot)],
    options={"resolution": "320x240", "hairball_triangles": 200_000, "short": False},
    quick={"resolution": "32x24", "hairball_triangles": 20_000, "short": True},
    extra={
        "bvh_bytes_per_ray": bvh_bytes_per_ray,
        "queue_at_pick": lambda r: ray_buffer(r).get("avg_queue_rays_at_pick"),
        "parked": lambda r: ray_buffer(r).get("parked"),
        "prefetch": prefetch_totals,
    },
)
