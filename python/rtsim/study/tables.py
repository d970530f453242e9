"""What the studies' tables and figures share: number formats, markdown tables, mismatch totals
and configurations set against each other per trace, the stats.json figures several studies
read (BVH bytes per ray, ray-buffer counters, prefetch totals), the `rtsim trace` scene entries
of the project's scenes, and matplotlib set up for files."""

from __future__ import annotations

from typing import Any

from rtsim.sweep.store import RunRecord


def fmt(value: Any, spec: str, none: str = "-") -> str:
    """`value` formatted by `spec`, or `none` when missing."""
    return none if value is None else format(value, spec)


def pct(x: float | None) -> str:
    """A fraction as a signed percentage with one decimal (`+1.5%`); n/a when missing."""
    return "n/a" if x is None else f"{100 * x:+.1f}%"


def change(a: float, b: float) -> str:
    """a against b as a signed whole percentage (`-35%`)."""
    return f"{100 * (a / b - 1):+.0f}%"


def kib(v: int) -> str:
    return f"{v // 1024} MiB" if v >= 1024 else f"{v} KiB"


def scene(name: str, hairball_triangles: int | None = None, **more: Any) -> dict[str, Any]:
    """A spec's scene entry (the hairball with its size)."""
    entry: dict[str, Any] = {"name": name, **more}
    if name == "hairball" and hairball_triangles:
        entry["hairball_triangles"] = hairball_triangles
    return entry


def markdown(header: list[str], align: str, rows: list[list[str]]) -> str:
    """A markdown table: `align` is one character per column, `l` or `r`."""
    rule = "|" + "|".join("---:" if a == "r" else "---" for a in align) + "|"
    lines = ["| " + " | ".join(header) + " |", rule]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines) + "\n"


def mismatches(rows: list[dict[str, Any]]) -> int:
    """Hit and work mismatches summed over the rows."""
    return sum((r["hit_mismatches"] or 0) + (r["work_mismatches"] or 0) for r in rows)


class ByConfig:
    """Rows by trace and configuration (their `trace` and `config` columns), for tables that
    set each configuration against another on the same trace (the execution-model studies)."""

    def __init__(self, rows: list[dict[str, Any]]) -> None:
        self.rows = {(r["trace"], r["config"]): r for r in rows}

    def against(self, row: dict[str, Any], base: str = "MIMD") -> float:
        """The row's Mrays/s over `base`'s on its trace."""
        return row["mrays_per_second"] / self.rows[(row["trace"], base)]["mrays_per_second"]

    def speed(self, trace: str, config: str, base: str = "MIMD") -> str:
        """`config`'s Mrays/s over `base`'s on `trace` (`1.25x`; `-` when either is missing)."""
        if (trace, config) not in self.rows or (trace, base) not in self.rows:
            return "-"
        return f"{self.against(self.rows[(trace, config)], base):.2f}x"

    def efficiency(self, trace: str, config: str) -> str:
        """`config`'s SIMD efficiency on `trace` (`-` when missing)."""
        return fmt((self.rows.get((trace, config)) or {}).get("simd_efficiency"), ".2f")


# Figures of stats.json several studies read, as extra columns of their DataFrame.


def _model(rec: RunRecord) -> dict[str, Any]:
    return (rec.stats or {}).get("model") or {}


def _rays(rec: RunRecord) -> int:
    return int(rec.summary.get("rays") or 1)


def bvh_bytes_per_ray(rec: RunRecord) -> float:
    """BVH bytes: node and triangle reads from DRAM, per ray."""
    dram = _model(rec).get("dram", {}).get("by_kind", {})
    return sum(dram.get(k, {}).get("read_bytes", 0) for k in ("node", "triangle")) / _rays(rec)


def ray_buffer(rec: RunRecord) -> dict[str, Any]:
    return _model(rec).get("ray_buffer") or {}


def prefetch_totals(rec: RunRecord) -> dict[str, int]:
    """Prefetch counters summed over the caches (only its target issues; the other counts 0),
    and `dram_bytes`: the DRAM traffic prefetching caused (the L2's reads below for it)."""
    model = _model(rec)
    total: dict[str, int] = {}
    for cache in [*model.get("l1", {}).values(), model.get("l2", {})]:
        for k, v in cache.get("prefetch", {}).items():
            total[k] = total.get(k, 0) + v
    if total:
        total["dram_bytes"] = model["l2"].get("prefetch", {}).get("below_bytes", 0)
    return total


def l1_misses(rec: RunRecord) -> int:
    """Read line accesses that missed in the L1s (merged misses count as hits, as hit_rate does)."""
    return sum(
        c.get("reads", 0) - c.get("read_hits", 0) - c.get("merged", 0)
        for c in (_model(rec).get("l1") or {}).values()
    )


def cycle_uses(rec: RunRecord) -> dict[str, float]:
    """Where the ray contexts' cycles went: `{use: fraction of context-cycles}`."""
    by_use = (_model(rec).get("cycle_accounting") or {}).get("by_use") or {}
    total = sum(by_use.values()) or 1
    return {k: v / total for k, v in by_use.items()}


def stack_prefetch_totals(rec: RunRecord) -> dict[str, int]:
    """The units' stack-prefetch counters (traversal.stack_prefetch), summed."""
    total: dict[str, int] = {}
    for u in units(rec):
        for k, v in (u.get("stack_prefetch") or {}).items():
            total[k] = total.get(k, 0) + v
    return total


def units(rec: RunRecord) -> list[dict[str, Any]]:
    """Every traversal unit's counters."""
    return list((_model(rec).get("units") or {}).values())


def pyplot() -> Any:
    """matplotlib's pyplot drawing into files (no display)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt
