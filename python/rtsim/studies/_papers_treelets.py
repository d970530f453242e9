"""Papers-study rows for treelets (Aila & Karras 2010) and treelet prefetching (Chou, Nowicki &
Aamodt 2023), measured by the treelet_factors study's points (rtsim/studies/treelet_factors.py)
on diffuse rays of Sponza and a 200k-triangle hairball at 320x240 (`short`: the options' smaller
resolution and hairball, five points)."""

from __future__ import annotations

from typing import Any

from rtsim.studies import treelet_factors
from rtsim.studies.treelet_factors import against
from rtsim.study import StudyRun

PART = "papers-treelets"
Row = dict[str, Any]


def _speed(rows: list[Row], r: Row) -> float:
    return r["mrays_per_second"] / against(rows, r)["mrays_per_second"]


def _cut(rows: list[Row], r: Row, key: str) -> str:
    return f"-{100 * (1 - r[key] / against(rows, r)[key]):.0f}%"


def _named(rows: list[Row], scene: str, name: str) -> Row:
    return next(r for r in rows if r["scene"] == scene and r["name"] == name)


def _best(rows: list[Row], scene: str, key: str) -> Row:
    """The treelet point of `scene` with the largest cut in `key` against its own baseline."""
    cand = [r for r in rows if r["scene"] == scene and r["treelets"]]
    return min(cand, key=lambda r: r[key] / against(rows, r)[key])


def aila_karras(rows: list[Row], scenes: list[str]) -> dict[str, str]:
    parts, why = [], []
    for scene in scenes:
        d = _named(rows, scene, "treelets (defaults)")
        b = _best(rows, scene, "bvh_bytes_per_ray")
        parts.append(
            f"{scene} diffuse: BVH DRAM bytes {_cut(rows, d, 'bvh_bytes_per_ray')} at the "
            f"defaults (all DRAM bytes {_cut(rows, d, 'dram_bytes_per_ray')}); at best "
            f"{_cut(rows, b, 'bvh_bytes_per_ray')} with {b['name']} (all "
            f"{_cut(rows, b, 'dram_bytes_per_ray')}, {_speed(rows, b):.2f}x Mrays/s)"
        )
        why.append(
            f"{scene}: {d['treelet_count']:,} treelets leave {d['queue_at_pick']:.0f} rays in a "
            f"queue when a unit picks it ({100 * d['drain_pick_fraction']:.0f}% drain picks), so "
            "a treelet load serves few rays"
        )
    return {
        "technique": "treelet ray queues (treelets.enabled)",
        "paper": "Aila & Karras 2010 (HPG)",
        "published": "up to 90% less total memory traffic in difficult scenes",
        "setup": "a massively parallel machine tracing incoherent (diffuse) rays in scenes of "
        "millions of triangles, BVHs far larger than the caches; total traffic including "
        "auxiliary traffic (stacks, queues)",
        "ours": "; ".join(parts),
        "why": "; ".join(why)
        + ". Our scenes are smaller (Sponza 262k, hairball 200k triangles) and one frame of rays "
        "bounds the batching; a ray returns to its ancestors' treelets after each subtree (parks "
        "per ray), and ray records, hits and stack spills, which treelets do not cut, count in "
        "the total (docs/treelets.md, 'What separates us from Aila & Karras')",
    }


def chou(rows: list[Row], scenes: list[str]) -> dict[str, str]:
    parts, why = [], []
    for scene in scenes:
        for name in ("prefetch into L1", "prefetch into L2"):
            r = _named(rows, scene, name)
            pf = r["prefetch"]
            used = 100 * pf["useful"] / max(pf["issued"], 1)
            dram = r["dram_bytes_per_ray"] / against(rows, r)["dram_bytes_per_ray"]
            parts.append(
                f"{scene} {name[9:]}: {_speed(rows, r):.2f}x Mrays/s, {used:.0f}% of prefetched "
                f"lines used, DRAM bytes {dram:.2f}x"
            )
        busy = 100 * _named(rows, scene, "treelets (defaults)")["dram_bandwidth_utilization"]
        why.append(f"{scene}: DRAM {busy:.0f}% busy without prefetching")
    return {
        "technique": "treelet prefetching (treelets.prefetch)",
        "paper": "Chou, Nowicki & Aamodt 2023 (MICRO)",
        "published": "+32.1% performance on average over the baseline RT unit, same power",
        "setup": "Vulkan-Sim RT unit of a GPU (warps of rays, a two-stack treelet traversal), "
        "treelets laid out contiguously and prefetched into the L1 when a ray reaches a treelet "
        "root",
        "ours": "against treelets without prefetching (16 KiB treelets, 512 KiB buffer): "
        + "; ".join(parts),
        "why": "; ".join(why)
        + ". Our MIMD units keep 16 rays in flight each and already hide much of the latency "
        "the prefetch hides on a warp-based RT unit; a prefetch takes only free MSHRs (at most "
        "half); our treelets keep their depth-first layout, so the prefetcher replays lines "
        "learnt on earlier visits (none on a treelet's first visit)",
    }


def specs(o: dict[str, Any]) -> list[dict[str, Any]]:
    res, triangles = o["treelets_resolution"], o["treelets_hairball_triangles"]
    return treelet_factors.spec(res, triangles, o["short"], PART)


def rows(run: StudyRun) -> list[dict[str, str]]:
    measured = treelet_factors.rows(run, PART)
    scenes = treelet_factors.SCENES
    return [aila_karras(measured, scenes), chou(measured, scenes)]
