"""The report's frame section: when a sweep's runs model the frame (`shading.enabled`), one row
per run with its frame time, breakdown, shading share, the Amdahl view, divergence, SIMD
efficiency and texture hit rate (docs/shading.md), so `shading.reorder` and the frame loop read
as axes like any other."""

from __future__ import annotations

from collections.abc import Callable
from html import escape
from typing import Any

from rtsim.report.data import SweepData

HEADER = [
    "scene",
    "workload",
    "configuration",
    "frame ms",
    "traversal",
    "reorder",
    "shading",
    "shading share",
    "2x RT buys",
    "programs/warp",
    "SIMD eff.",
    "tex hit",
]


def _pct(x: Any) -> str:
    return "-" if not isinstance(x, (int, float)) else f"{100 * x:.1f}%"


def frame_section(data: SweepData, table: Callable[..., str]) -> list[str]:
    rows = []
    for rec in data.runs:
        sh = ((rec.stats or {}).get("model") or {}).get("shading")
        if not sh:
            continue
        frame, b = sh["frame_cycles"], sh["breakdown"]
        share = [b[k] / frame if frame else None for k in ("traversal", "reorder", "shading")]
        rows.append(
            [
                escape(rec.scene),
                escape(rec.workload),
                escape(data.label(rec)),
                f"{sh['frame_ms']:.4f}",
                *(_pct(x) for x in share),
                _pct(sh["shading_share"]),
                f"{sh['amdahl']['speedup_2x_rt']:.2f}x",
                f"{sh['divergence']:.2f}",
                _pct(sh["simd_efficiency"]),
                _pct(sh["tex_hit_rate"]),
            ]
        )
    if not rows:
        return []
    return [
        "<h2>The frame</h2>",
        "<p>Runs with <code>shading.enabled</code>: the frame from ray generation to the last ray "
        "shaded and where its time went (the breakdown sums to the frame), the share not in "
        "traversal beside the source text's 'at least 50%', what a 2x faster RT unit buys the "
        "frame, and the shader cores' divergence, SIMD efficiency and texture hit rate "
        "(docs/shading.md).</p>",
        table(HEADER, rows, set(range(3, len(HEADER)))),
    ]
