"""The short table `rtsim trace` prints: rays per kind, hits, BVH, effects and why."""

from __future__ import annotations

from typing import Any

from rich.console import Console
from rich.table import Table

from rtsim.kinds import RAY_KINDS
from rtsim.manifest import find


def _num(value: Any, digits: int = 2) -> str:
    if isinstance(value, bool) or value is None:
        return "-" if value is None else str(value)
    if isinstance(value, int):
        return f"{value:,}"
    if isinstance(value, float):
        return f"{value:,.{digits}f}"
    return str(value)


def ray_table(manifest: dict[str, Any]) -> Table:
    table = Table(title="rays", title_justify="left")
    for column in ("kind", "traced", "hits", "hit rate", "steps/ray", "tris/ray"):
        table.add_column(column, justify="left" if column == "kind" else "right")
    by_kind = find(manifest, "counts.by_kind", "by_kind", default={}) or {}
    if isinstance(by_kind, dict):
        order = {kind: i for i, kind in enumerate(RAY_KINDS)}
        for kind, stats in sorted(by_kind.items(), key=lambda kv: order.get(kv[0], len(order))):
            if not isinstance(stats, dict):
                continue
            hit_rate = stats.get("hit_rate")
            table.add_row(
                kind,
                _num(stats.get("traced", stats.get("rays"))),
                _num(stats.get("hits")),
                f"{hit_rate:.1%}" if isinstance(hit_rate, (int, float)) else "-",
                _num(stats.get("steps_per_ray"), 1),
                _num(stats.get("tri_tests_per_ray"), 1),
            )
    return table


def scene_table(manifest: dict[str, Any]) -> Table:
    table = Table(title="scene and acceleration structure", title_justify="left", show_header=False)
    table.add_column("what")
    table.add_column("value", justify="right")
    rows = [
        ("scene", find(manifest, "scene.name")),
        ("triangles", find(manifest, "scene.triangles")),
        ("instances", find(manifest, "scene.instances")),
        ("structure", find(manifest, "accel.kind")),
        ("nodes", find(manifest, "accel.nodes")),
        ("leaves", find(manifest, "accel.leaves")),
        ("SAH cost", find(manifest, "accel.sah_cost")),
        ("footprint (bytes)", find(manifest, "accel.footprint_bytes")),
        ("rays written", find(manifest, "counts.rays")),
        ("rays rejected", find(manifest, "counts.rejected")),
        ("trace time (ms)", find(manifest, "timing_ms.trace")),
    ]
    for label, value in rows:
        if value is not None:
            table.add_row(label, _num(value))
    return table


def effects_table(manifest: dict[str, Any]) -> Table:
    table = Table(title="effects", title_justify="left")
    table.add_column("effect")
    table.add_column("simulated")
    table.add_column("why")
    effects = find(manifest, "workload.effects", "effects", default=[]) or []
    if isinstance(effects, dict):
        effects = [
            {"name": k, **(v if isinstance(v, dict) else {"why": v})} for k, v in effects.items()
        ]
    for effect in effects if isinstance(effects, list) else []:
        if isinstance(effect, dict):
            simulated = effect.get("simulated")
            mark = "yes" if simulated else ("no" if simulated is not None else "-")
            table.add_row(str(effect.get("name", "?")), mark, str(effect.get("why", "")))
    return table


def print_summary(manifest: dict[str, Any], console: Console | None = None) -> None:
    console = console or Console()
    console.print(scene_table(manifest))
    console.print(ray_table(manifest))
    console.print(effects_table(manifest))
