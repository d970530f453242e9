"""Short stacks' rows of the papers study (docs/papers.md): Vaidyanathan, Woop & Benthin 2019 and
Laine 2010 set beside our short stack with a restart trail (docs/accel.md, "Short stacks").

The shortstack study's points (rtsim/studies/shortstack.py) on cwbvh8 and bvh2: Sponza and a
50k-triangle hairball at 160x120 (`short`: Sponza at 64x48, entries 1, 2 and 5)."""

from __future__ import annotations

from typing import Any

from rtsim.studies import shortstack
from rtsim.study import StudyRun

PART = "papers-shortstack"


def options(o: dict[str, Any]) -> dict[str, Any]:
    """The shortstack study's options these rows run with."""
    short = o["short"]
    return {
        **shortstack.STUDY.options,
        "accels": ["cwbvh8", "bvh2"],
        "resolution": o["shortstack_resolution"],
        "scenes": ["sponza"] if short else ["sponza", "hairball"],
        "entries": [1, 2, 5] if short else [1, 2, 3, 5, 8],
    }


def specs(o: dict[str, Any]) -> list[dict[str, Any]]:
    return shortstack.spec_of(options(o), PART)


def _pick(rows: list[dict[str, Any]], scene: str, accel: str, run: str) -> dict[str, Any]:
    return next(r for r in rows if (r["scene"], r["accel"], r["run"]) == (scene, accel, run))


def _ours(rows: list[dict[str, Any]], scenes: list[str], accel: str, runs: list[str]) -> str:
    parts = []
    for scene in scenes:
        for run in runs:
            r = _pick(rows, scene, accel, run)
            parts.append(
                f"{scene} {accel}, {r['entries']} entr{'y' if r['entries'] == 1 else 'ies'}: "
                f"{100 * r['extra_steps']:+.1f}% node steps, "
                f"{r['restarts_per_ray']:.2f} restarts/ray, "
                f"{r['speed_vs_full']:.2f}x the full stack's Mrays/s"
            )
    return "; ".join(parts)


def _extra(rows: list[dict[str, Any]], scene: str, entries: int) -> str:
    both = [_pick(rows, scene, a, f"short{entries}") for a in ("bvh2", "cwbvh8")]
    return f"{entries} entries on {scene}: " + ", ".join(
        f"{r['accel']} {100 * r['extra_steps']:+.1f}% node steps" for r in both
    )


def rows(run: StudyRun) -> list[dict[str, str]]:
    found = shortstack.rows(run, PART)
    opts = options(run.options)
    scenes = opts["scenes"]
    setup = (
        f"{opts['workload']} rays at {opts['resolution']}, default machine (approx "
        "level), restart trail against a 64-entry stack that never spills"
    )
    return [
        {
            "technique": "Short stack with a restart trail, wide BVH",
            "paper": "Vaidyanathan, Woop & Benthin, "
            "Wide BVH Traversal with a Short Stack, HPG 2019",
            "published": "traversal steps with 5 stack entries close to a full stack's "
            "(compressed wide BVHs, incoherent rays)",
            "setup": setup,
            "ours": _ours(found, scenes, "cwbvh8", ["short2", "short5"]),
            "why": "Counted the same way: node steps the restarts revisit over the full "
            "stack's. Our re-descent revisits the resumed entry's ancestors from the root, as a "
            "trail does; the paper's leaf culling after a closer hit is not modelled. The paper "
            "counts steps; our speed also depends on whether revisited nodes hit in the caches.",
        },
        {
            "technique": "Restart trail, binary BVH",
            "paper": "Laine, Restart Trail for Stackless BVH Traversal, HPG 2010",
            "published": "one bit per level makes restarts (stackless and short-stack traversal) "
            "possible in a BVH; measured against a full stack on GPUs in CUDA",
            "setup": setup,
            "ours": _ours(found, scenes, "bvh2", ["short1", "short5"]),
            "why": "A binary node pushes at most one entry, a wide one up to seven, so at the "
            "same size a wide BVH's short stack overflows sooner "
            f"({_extra(found, scenes[0], 5)}); a binary tree is about twice as deep, so each "
            "restart revisits more levels. Each revisit is charged a node fetch and its box "
            "tests; the trail's bits are free.",
        },
    ]
