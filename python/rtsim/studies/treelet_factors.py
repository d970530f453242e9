"""What separates rtsim's treelet savings from Aila & Karras 2010's "up to 90%", one factor at a
time, and what treelet prefetching (Chou, Nowicki & Aamodt 2023) adds (docs/treelets.md).

On diffuse rays of Sponza and a procedural hairball, each point changes one thing from the
treelet default (16 KiB treelets, 512 KiB ray buffer, `largest` policy, 1 MiB L2): the L2 against
the scene, rays in flight, treelet size, scheduling, prefetching and the combinations the factors
point to. Tables between the `treelet-factors` and `treelet-prefetch` markers of docs/treelets.md;
the papers study reads the same points (rtsim/studies/papers.py)."""

from __future__ import annotations

from typing import Any

from rtsim.study import Study, StudyRun, Table
from rtsim.study.tables import bvh_bytes_per_ray, change, prefetch_totals, ray_buffer, scene

SCENES = ["sponza", "hairball"]
TREELETS = {"treelets.enabled": True}


def tl(name: str, factor: str, baseline: str = "base", **sets: Any) -> dict[str, Any]:
    """A treelet point: its name (the row), the factor it varies, the point it is compared with."""
    return {
        "name": name,
        "factor": factor,
        "baseline": baseline,
        "set": {**TREELETS, **{k.replace("__", "."): v for k, v in sets.items()}},
    }


def off(name: str, factor: str, **sets: Any) -> dict[str, Any]:
    return {
        "name": name,
        "factor": factor,
        "baseline": "base",
        "set": {k.replace("__", "."): v for k, v in sets.items()},
    }


POINTS = [
    off("baseline", "reference"),
    tl("treelets (defaults)", "reference"),
    off("baseline, L2 256 KiB", "scene against L2", l2__size_kib=256),
    tl("treelets, L2 256 KiB", "scene against L2", "baseline, L2 256 KiB", l2__size_kib=256),
    off("baseline, L2 4 MiB", "scene against L2", l2__size_kib=4096),
    tl("treelets, L2 4 MiB", "scene against L2", "baseline, L2 4 MiB", l2__size_kib=4096),
    tl("buffer 2 MiB", "rays in flight", treelets__buffer_kib=2048),
    tl("buffer 8 MiB", "rays in flight", treelets__buffer_kib=8192),
    tl("treelets 8 KiB", "treelet size", treelets__treelet_kib=8),
    tl("treelets 32 KiB", "treelet size", treelets__treelet_kib=32),
    tl("treelets 64 KiB", "treelet size", treelets__treelet_kib=64),
    tl("policy oldest", "scheduling", treelets__policy="oldest"),
    tl("policy round_robin", "scheduling", treelets__policy="round_robin"),
    tl("prefetch into L1", "prefetching", "treelets (defaults)", treelets__prefetch=True),
    tl(
        "prefetch into L2",
        "prefetching",
        "treelets (defaults)",
        treelets__prefetch=True,
        treelets__prefetch_into="l2",
    ),
    tl(
        "prefetch 32 lines into L1",
        "prefetching",
        "treelets (defaults)",
        treelets__prefetch=True,
        treelets__prefetch_lines=32,
    ),
    tl(
        "prefetch 32 lines into L2",
        "prefetching",
        "treelets (defaults)",
        treelets__prefetch=True,
        treelets__prefetch_lines=32,
        treelets__prefetch_into="l2",
    ),
    tl(
        "32 KiB treelets, 8 MiB buffer",
        "combined",
        treelets__treelet_kib=32,
        treelets__buffer_kib=8192,
    ),
    tl(
        "32 KiB treelets, 8 MiB buffer, L2 256 KiB",
        "combined",
        "baseline, L2 256 KiB",
        treelets__treelet_kib=32,
        treelets__buffer_kib=8192,
        l2__size_kib=256,
    ),
    tl(
        "32 KiB treelets, 8 MiB buffer, prefetch into L1",
        "combined",
        "32 KiB treelets, 8 MiB buffer",
        treelets__treelet_kib=32,
        treelets__buffer_kib=8192,
        treelets__prefetch=True,
    ),
]
QUICK = ["baseline", "treelets (defaults)", "buffer 2 MiB", "prefetch into L1", "prefetch into L2"]
BY_NAME = {p["name"]: p for p in POINTS}


def spec(resolution: str, hairball_triangles: int, quick: bool, name: str) -> list[dict[str, Any]]:
    """One spec per scene (the table's order): every factor point on its diffuse rays."""
    points = [p for p in POINTS if not quick or p["name"] in QUICK]
    return [
        {
            "name": f"{name}-{s}",
            "scenes": [scene(s, hairball_triangles)],
            "workloads": [{"name": "diffuse", "rays": ["diffuse"], "resolution": resolution}],
            "points": [{"label": p["name"], "set": p["set"]} for p in points],
        }
        for s in SCENES
    ]


def specs(o: dict[str, Any]) -> list[dict[str, Any]]:
    return spec(o["resolution"], o["hairball_triangles"], o["short"], "treelet-factors")


def rows(run: StudyRun, part: str = "treelet-factors") -> list[dict[str, Any]]:
    """The factor points' rows, in the old study's terms (name, factor, baseline, ...)."""
    out = []
    for r in run.rows():
        if not r["part"].startswith(part):
            continue
        p, rays = BY_NAME[r["point"]], r["rays"]
        on = bool(r["treelets.enabled"])
        out.append(
            {
                "scene": r["scene"],
                "name": p["name"],
                "factor": p["factor"],
                "baseline": p["baseline"],
                "treelets": on,
                "rays": rays,
                "dram_bytes_per_ray": r["dram_bytes_per_ray"],
                "bvh_bytes_per_ray": r["bvh_bytes_per_ray"],
                "l2_read_bytes_per_ray": r["l2_read_bytes"] / rays,
                "mrays_per_second": r["mrays_per_second"],
                "dram_bandwidth_utilization": r["dram_bandwidth_utilization"],
                "treelet_count": r["treelet_count"],
                "queue_at_pick": r["queue_at_pick"],
                "drain_pick_fraction": r["drain_pick_fraction"],
                "parks_per_ray": r["parked"] / rays if on else None,
                "prefetch": r["prefetch"],
            }
        )
    return out


def against(rows: list[dict[str, Any]], r: dict[str, Any]) -> dict[str, Any]:
    name = "baseline" if r["baseline"] == "base" else r["baseline"]
    return next(b for b in rows if b["scene"] == r["scene"] and b["name"] == name)


def factor_table(rows: list[dict[str, Any]]) -> str:
    out = [
        "| scene | factor | config | BVH B/ray | vs its baseline | DRAM B/ray | vs its baseline | "
        "L2 read B/ray | Mrays/s | vs its baseline | queue at pick | drain picks | parks/ray |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        b = against(rows, r)
        same = b is r
        cut_bvh = "" if same else change(r["bvh_bytes_per_ray"], b["bvh_bytes_per_ray"])
        cut_dram = "" if same else change(r["dram_bytes_per_ray"], b["dram_bytes_per_ray"])
        speed = "" if same else f"{r['mrays_per_second'] / b['mrays_per_second']:.2f}x"
        queue = " | | |"
        if r["treelets"]:
            drains = 100 * r["drain_pick_fraction"]
            queue = f"{r['queue_at_pick']:.0f} | {drains:.0f}% | {r['parks_per_ray']:.1f} |"
        out.append(
            f"| {r['scene']} | {r['factor']} | {r['name']} | {r['bvh_bytes_per_ray']:.0f} | "
            f"{cut_bvh} | {r['dram_bytes_per_ray']:.0f} | {cut_dram} | "
            f"{r['l2_read_bytes_per_ray']:.0f} | {r['mrays_per_second']:.1f} | {speed} | " + queue
        )
    return "\n".join(out) + "\n"


def prefetch_table(rows: list[dict[str, Any]]) -> str:
    out = [
        "| scene | config | Mrays/s | vs no prefetch | DRAM B/ray | prefetch DRAM B/ray | "
        "lines issued/ray | useful | of which late | useless (evicted unused) | still resident |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        pf = r["prefetch"]
        if not pf.get("issued"):
            continue
        b, n, rays = against(rows, r), pf["issued"], r["rays"]
        speed = r["mrays_per_second"] / b["mrays_per_second"]
        late = 100 * pf["late"] / max(pf["useful"], 1)
        out.append(
            f"| {r['scene']} | {r['name']} | {r['mrays_per_second']:.1f} | {speed:.2f}x | "
            f"{r['dram_bytes_per_ray']:.0f} | {pf['dram_bytes'] / rays:.0f} | {n / rays:.1f} | "
            f"{100 * pf['useful'] / n:.0f}% | {late:.0f}% | {100 * pf['useless'] / n:.0f}% | "
            f"{100 * pf['resident'] / n:.0f}% |"
        )
    return "\n".join(out) + "\n"


def note(run: StudyRun) -> str:
    o, m = run.options, run.measured()
    return (
        f"Measured with `{run.command}` (diffuse rays at {o['resolution']}, hairball "
        f"{o['hairball_triangles']:,} triangles, default config otherwise; rtsim-sim git "
        f"{m['git']}; {m['date']}). One run per point (the model is deterministic). BVH = node + "
        "triangle reads from DRAM; every run has 0 hit and 0 work mismatches.\n\n"
    )


#: The extra columns these points' rows read from stats.json (the papers study shares them).
EXTRA = {
    "bvh_bytes_per_ray": bvh_bytes_per_ray,
    "l2_read_bytes": "model.l2.read_bytes",
    "treelet_count": lambda r: ray_buffer(r).get("treelets", {}).get("count"),
    "queue_at_pick": lambda r: ray_buffer(r).get("avg_queue_rays_at_pick"),
    "drain_pick_fraction": lambda r: (
        ray_buffer(r)["drain_picks"] / ray_buffer(r)["picks"]
        if ray_buffer(r).get("picks")
        else None
    ),
    "parked": lambda r: ray_buffer(r).get("parked"),
    "prefetch": prefetch_totals,
}

STUDY = Study(
    name="treelet_factors",
    about="treelet savings against Aila & Karras 2010, one factor at a time, and prefetching",
    specs=specs,
    tables=[
        Table("treelets.md", "treelet-factors", lambda run: note(run) + factor_table(rows(run))),
        Table("treelets.md", "treelet-prefetch", lambda run: note(run) + prefetch_table(rows(run))),
    ],
    options={"resolution": "320x240", "hairball_triangles": 200_000, "short": False},
    quick={"resolution": "32x24", "hairball_triangles": 20_000, "short": True},
    extra=EXTRA,
)
