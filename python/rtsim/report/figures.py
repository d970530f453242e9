"""The report's matplotlib figures. Each function takes the sweep's data and returns a Figure
(or None when the sweep has nothing to draw for it); html.py embeds them as PNG."""

from __future__ import annotations

import math
import statistics
from collections.abc import Callable
from typing import Any

import matplotlib
import matplotlib.ticker

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.figure import Figure

from rtsim.kinds import DATA_KINDS
from rtsim.report.data import (
    COSTS,
    Group,
    SweepData,
    axis_label,
    key_active,
    mrays,
    param,
    pareto_front,
    short_label,
)
from rtsim.sweep.results import bytes_per_ray_by_kind
from rtsim.sweep.store import RunRecord

KIND_COLORS = {
    "node": "#4C72B0",
    "triangle": "#DD8452",
    "ray": "#55A868",
    "hit": "#C44E52",
    "stack": "#8172B3",
    "ray_buffer": "#937860",
    "cell": "#DA8BC3",
    "prim_ref": "#8C8C8C",
}
KIND_NAMES = {
    "node": "BVH nodes",
    "triangle": "triangles",
    "ray": "rays",
    "hit": "hits",
    "stack": "stack spills",
    "ray_buffer": "ray-buffer spills",
    "cell": "grid cells",
    "prim_ref": "primitive references",
}
#: Colours for kinds a structure adds that are not named above (never dropped from a chart).
EXTRA_KIND_COLORS = ("#CCB974", "#64B5CD", "#2F4B7C", "#A05195")


def kinds_present(breakdowns: list[dict[str, float]]) -> list[str]:
    """Every data kind with traffic in any breakdown: the known kinds in their order, then any
    other (a structure's own regions, e.g. a grid's cells and primitive references) by name.
    A kind left out would make the stacked bars short of the run's total."""
    moved = {k for kinds in breakdowns for k, v in kinds.items() if v}
    known = [k for k in (*DATA_KINDS, *KIND_COLORS) if k in moved]
    known = list(dict.fromkeys(known))
    return known + sorted(moved - set(known))


def kind_style(kind: str, index: int) -> tuple[str, str]:
    """(colour, legend name) of a data kind."""
    color = KIND_COLORS.get(kind, EXTRA_KIND_COLORS[index % len(EXTRA_KIND_COLORS)])
    return color, KIND_NAMES.get(kind, kind.replace("_", " "))


MAX_BARS = 24

plt.rcParams.update(
    {
        "font.size": 11,
        "axes.titlesize": 12,
        "axes.labelsize": 11,
        "figure.titlesize": 14,
        "legend.fontsize": 10,
        "axes.grid": True,
        "grid.alpha": 0.3,
        "axes.spines.top": False,
        "axes.spines.right": False,
    }
)


def _panels(n: int, width: float, height: float, ncols: int = 2) -> tuple[Figure, list[Any]]:
    ncols = min(ncols, n)
    nrows = math.ceil(n / ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(width * ncols, height * nrows), squeeze=False)
    flat = list(axes.flat)
    for ax in flat[n:]:
        ax.set_visible(False)
    return fig, flat[:n]


def _line_colors(n: int) -> list[Any]:
    cmap = plt.get_cmap("tab10")
    return [cmap(i % 10) for i in range(n)]


def _breakdown_clusters(data: SweepData, g: Group) -> list[tuple[str, dict[str, float]]]:
    """The group's runs merged where their breakdown agrees within 1%: (label, bytes by kind)."""
    clusters: list[tuple[list[RunRecord], dict[str, float]]] = []
    # The baseline is its own bar, never folded into another configuration's "(+N alike)".
    base = data.baseline_run(g.ok)
    out = (
        []
        if base is None
        else [(f"{g.title}: {data.label(base)} (baseline)", bytes_per_ray_by_kind(base))]
    )
    rest = [r for r in g.ok if r is not base]
    for r in sorted(rest, key=lambda r: sum(bytes_per_ray_by_kind(r).values())):
        kinds = bytes_per_ray_by_kind(r)
        for runs, ref in clusters:
            tol = 0.01 * max(sum(ref.values()), 1e-9)
            if all(abs(kinds.get(k, 0) - ref.get(k, 0)) <= tol for k in {*kinds, *ref}):
                runs.append(r)
                break
        else:
            clusters.append(([r], kinds))
    for runs, kinds in clusters[: MAX_BARS - len(out)]:
        if len(runs) == len(rest) and len(runs) > 1 and base is None:
            label = f"all {len(runs)} configurations"
        else:
            label = data.label(runs[0]) + (f" (+{len(runs) - 1} alike)" if len(runs) > 1 else "")
        out.append((f"{g.title}: {label}", kinds))
    return out


def bytes_per_ray(data: SweepData) -> Figure | None:
    bars = [b for g in data.groups() if g.ok for b in _breakdown_clusters(data, g)]
    if not bars:
        return None
    present = kinds_present([kinds for _, kinds in bars])
    fig, ax = plt.subplots(figsize=(12, 0.42 * len(bars) + 1.8))
    labels = [label for label, _ in bars][::-1]
    left = [0.0] * len(bars)
    for i, kind in enumerate(present):
        vals = [kinds.get(kind, 0.0) for _, kinds in bars][::-1]
        color, name = kind_style(kind, i)
        ax.barh(labels, vals, left=left, color=color, label=name)
        left = [a + b for a, b in zip(left, vals, strict=True)]
    for y, total in enumerate(left):
        ax.annotate(
            f"{total:.0f} B",
            (total, y),
            xytext=(4, 0),
            textcoords="offset points",
            va="center",
            fontsize=9,
        )
    ax.set_xlabel("DRAM bytes per ray (read + write)")
    ax.set_xlim(right=max(left) * 1.1)
    ax.grid(axis="y", visible=False)
    ax.legend(loc="lower center", bbox_to_anchor=(0.5, 1.0), ncol=len(present), frameon=False)
    fig.suptitle("DRAM traffic per ray by data kind (configurations within 1% merged)")
    fig.tight_layout()
    return fig


def bandwidth_over_time(data: SweepData) -> Figure | None:
    groups = [g for g in data.groups() if any(_bw_series(r) for r in g.ok)]
    if not groups:
        return None
    fig, axes = _panels(len(groups), 7.0, 4.6)
    for ax, g in zip(axes, groups, strict=True):
        runs = sorted((r for r in g.ok if _bw_series(r)), key=mrays)
        picks = {"slowest": runs[0], "median": runs[len(runs) // 2], "fastest": runs[-1]}
        seen = set()
        for (what, r), color in zip(picks.items(), ("#C44E52", "#8C8C8C", "#4C72B0"), strict=True):
            if r.run_id in seen:
                continue
            seen.add(r.run_id)
            t, gbps = _bw_series(r)
            ax.plot(
                t,
                gbps,
                color=color,
                lw=1.4,
                label=f"{what}: {data.label(r)} ({mrays(r):.0f} Mrays/s)",
            )
            peak = (r.stats or {}).get("model", {}).get("dram", {}).get("peak_bandwidth_gbps")
            if peak:
                ax.axhline(peak, color=color, ls="--", lw=1, alpha=0.7)
        ax.set_title(f"{g.title}  (dashed: peak bandwidth)")
        ax.set_xlabel("simulated time (µs)")
        ax.set_ylabel("DRAM bandwidth (GB/s)")
        ax.set_ylim(bottom=0)
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), fontsize=9, frameon=False)
    fig.suptitle("DRAM bandwidth over time: the slowest, median and fastest configuration")
    fig.tight_layout()
    return fig


def _bw_series(r: RunRecord) -> tuple[list[float], list[float]] | None:
    series = (r.stats or {}).get("model", {}).get("dram", {}).get("bandwidth_over_time") or []
    if not series:
        return None
    clock = float(r.config.get("clock_ghz", 1.0))
    return [p["cycle"] / clock / 1000 for p in series], [p["gbps"] for p in series]


def _numeric(values: list[Any]) -> bool:
    return all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)


LINE_STYLES = ("-", "--", ":", "-.")


def _categories(data: SweepData, key: str, runs: list[RunRecord]) -> dict[str, list[RunRecord]]:
    """Runs split by the categorical swept keys other than `key` (treelets on/off, a preset):
    a marginal plot over such runs would mix two machines in one line. Keys a run leaves inactive
    (a ray-buffer size with treelets off) do not split it."""
    cats = [k for k in data.categorical_keys() if k != key]
    out: dict[str, list[RunRecord]] = {}
    for r in runs:
        name = " · ".join(
            short_label(k, v)
            for k in cats
            if (v := param(r, k)) is not None and key_active(k, r.config)
        )
        out.setdefault(name, []).append(r)
    return out


def _versus_key(
    ax: Any,
    data: SweepData,
    key: str,
    groups: list[Group],
    metric: Callable[[RunRecord], float | None],
    name: Callable[[Group], str] = lambda g: g.title,
) -> None:
    """metric against one swept key: a line per group and category (the other categorical keys)
    through the median over the other numeric keys, a band from min to max."""
    values = sorted({v for g in groups for r in g.ok if (v := param(r, key)) is not None}, key=str)
    numeric = _numeric(values)
    if numeric:
        values = sorted(values)
    xs = {v: (v if numeric else i) for i, v in enumerate(values)}
    for g, color in zip(groups, _line_colors(len(groups)), strict=True):
        cats = _categories(data, key, g.ok)
        for (cat, runs), ls in zip(cats.items(), LINE_STYLES * 4, strict=False):
            by_value: dict[Any, list[float]] = {}
            for r in runs:
                m, v = metric(r), param(r, key)
                if v is not None and m is not None:
                    by_value.setdefault(v, []).append(m)
            vs = [v for v in values if v in by_value]
            if not vs:
                continue
            x = [xs[v] for v in vs]
            label = name(g) + (f" · {cat}" if cat else "")
            ax.plot(
                x,
                [statistics.median(by_value[v]) for v in vs],
                marker="o",
                ls="" if numeric and len(values) > 8 else ls,  # sampled keys: points only
                color=color,
                label=label,
            )
            ax.fill_between(
                x,
                [min(by_value[v]) for v in vs],
                [max(by_value[v]) for v in vs],
                color=color,
                alpha=0.10,
                lw=0,
            )
    _key_axis(ax, values, numeric, xs)
    ax.set_xlabel(axis_label(key))


def _powers_of_two(values: list[Any]) -> bool:
    return all(
        isinstance(v, int) and not isinstance(v, bool) and v > 0 and v & (v - 1) == 0
        for v in values
    )


def _key_axis(ax: Any, values: list[Any], numeric: bool, xs: dict[Any, Any]) -> None:
    """Swept values as ticks; a log-2 axis for wide numeric ranges, labelled with the plain
    values (16, 32, 64), never 2^4."""
    if numeric and len(values) > 1 and min(values) > 0 and max(values) / min(values) >= 4:
        ax.set_xscale("log", base=2)
    if not numeric or len(values) <= 8:
        ax.set_xticks([xs[v] for v in values], [_tick(v) for v in values])
    elif ax.get_xscale() == "log" and _powers_of_two(values):
        ax.xaxis.set_major_locator(matplotlib.ticker.LogLocator(base=2))
        ax.xaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}"))
    else:  # sampled keys: every run has its own value
        ax.xaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:.3g}"))
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.minorticks_off()


def _tick(v: Any) -> str:
    if isinstance(v, bool):
        return "on" if v else "off"
    return f"{v:.3g}" if isinstance(v, float) else str(v)


def rays_per_second(data: SweepData) -> Figure | None:
    groups = [g for g in data.groups() if g.ok]
    keys = [k for k in data.keys if any(param(r, k) is not None for g in groups for r in g.ok)]
    if not groups or not keys:
        return None
    scenes = list(dict.fromkeys(g.scene for g in groups))
    fig, axes = plt.subplots(
        len(scenes), len(keys), figsize=(4.8 * len(keys), 3.6 * len(scenes)), squeeze=False
    )
    for row, scene in enumerate(scenes):
        for col, key in enumerate(keys):
            ax = axes[row][col]
            # A row per scene: the lines are named by workload (and category) alone.
            row_groups = [g for g in groups if g.scene == scene]
            _versus_key(ax, data, key, row_groups, mrays, lambda g: g.workload)
            ax.set_ylabel("simulated Mrays/s")
            ax.set_ylim(bottom=0)
            ax.set_title(f"{scene}: rays/s against {key}", fontsize=11)
    fig.suptitle(
        "Performance against each swept key (line: median over the other keys; band: min to max)"
    )
    fig.tight_layout()
    _fig_legend(fig)
    return fig


def _fig_legend(fig: Figure) -> None:
    """One legend for the figure: every labelled line of every panel, each name once (a line
    only some panels draw, a category or a workload of another scene's row, is named too)."""
    handles, names = [], []
    for a in fig.axes:
        for h, n in zip(*a.get_legend_handles_labels(), strict=True):
            if n not in names:
                handles.append(h)
                names.append(n)
    if not names:
        return
    # Below every panel: above them it ran into the panels' titles once it took two rows, and
    # inside one it hides points. The report saves with bbox_inches="tight", which keeps it.
    fig.legend(
        handles,
        names,
        loc="upper center",
        bbox_to_anchor=(0.5, 0.0),
        ncol=min(len(names), 4),
        frameon=False,
    )


def hit_rates(data: SweepData) -> Figure | None:
    groups = [g for g in data.groups() if g.ok]
    keys = [k for k in data.keys if any(param(r, k) is not None for g in groups for r in g.ok)]
    if not groups or not keys:
        return None
    fig, axes = plt.subplots(2, len(keys), figsize=(4.8 * len(keys), 7.4), squeeze=False)
    for row, level in enumerate(("l1", "l2")):

        def metric(r: RunRecord, level: str = level) -> float | None:
            v = r.summary.get(f"{level}_hit_rate")
            return None if v is None else 100 * v

        for col, key in enumerate(keys):
            ax = axes[row][col]
            _versus_key(ax, data, key, groups, metric)
            ax.set_ylim(0, 102)
            ax.set_ylabel(f"{level.upper()} hit rate (%)")
            ax.set_title(f"{level.upper()} hit rate against {key}", fontsize=11)
    fig.suptitle("Cache hit rates per level (reads served, including merged misses)")
    fig.tight_layout()
    _fig_legend(fig)
    return fig


def pareto(
    data: SweepData, cost_name: str = "sram"
) -> tuple[Figure | None, dict[str, list[RunRecord]]]:
    """Rays/s against a cost (COSTS: on-chip SRAM, chip area, energy per ray) with the Pareto
    front per scene and workload."""
    cost = COSTS[cost_name]
    groups = [g for g in data.groups() if any(cost.of(r) is not None for r in g.ok)]
    if not groups:
        return None, {}
    fig, axes = _panels(len(groups), 7.0, 4.6)
    fronts: dict[str, list[RunRecord]] = {}
    for ax, g in zip(axes, groups, strict=True):
        runs = [r for r in g.ok if cost.of(r) is not None]
        xs = [float(cost.of(r) or 0) for r in runs]
        ax.scatter(
            xs,
            [mrays(r) for r in runs],
            s=22,
            color="#A0A0A0",
            label="every configuration",
            zorder=2,
        )
        front = pareto_front(runs, cost.of)
        fronts[g.title] = front
        ax.plot(
            [cost.of(r) for r in front],
            [mrays(r) for r in front],
            "o-",
            color="#C44E52",
            drawstyle="steps-post",
            label="Pareto front",
            zorder=3,
        )
        for i, r in enumerate(front):
            ax.annotate(
                f"{i + 1}",
                (float(cost.of(r) or 0), mrays(r)),
                textcoords="offset points",
                xytext=(-4, 7),
                fontsize=10,
                fontweight="bold",
                color="#C44E52",
            )
        _cost_axis(ax, xs, cost.unit)
        ax.set_xlabel(cost.axis)
        ax.set_ylabel("simulated Mrays/s")
        ax.set_ylim(bottom=0, top=max(mrays(r) for r in runs) * 1.15)
        ax.set_title(f"{g.title}  (numbers: table below)")
    fig.suptitle(f"Performance against {cost.name}: the Pareto front (up and left is better)")
    fig.tight_layout()
    _fig_legend(fig)
    return fig, fronts


def speedup(data: SweepData) -> Figure | None:
    """Each configuration's rays/s over the baseline configuration's, per scene and workload."""
    panels = []
    for g in data.groups():
        base = data.baseline_run(g.ok)
        if base is None or mrays(base) <= 0 or len(g.ok) < 2:
            continue
        bars = sorted(((data.label(r), mrays(r) / mrays(base), r is base) for r in g.ok),
                      key=lambda b: b[1])  # fmt: skip
        if len(bars) > MAX_BARS:  # the slowest and fastest, and the baseline
            keep = bars[: MAX_BARS // 2] + bars[-MAX_BARS // 2 :]
            bars = sorted({*keep, *(b for b in bars if b[2])}, key=lambda b: b[1])
        panels.append((g, base, bars))
    if not panels:
        return None
    rows = max(len(b) for _, _, b in panels)
    fig, axes = _panels(len(panels), 7.0, 0.32 * rows + 1.6)
    for ax, (g, base, bars) in zip(axes, panels, strict=True):
        colors = ["#8C8C8C" if is_base else ("#4C72B0" if x >= 1 else "#C44E52")
                  for _, x, is_base in bars]  # fmt: skip
        ax.barh([b[0] for b in bars], [b[1] for b in bars], color=colors)
        ax.axvline(1.0, color="black", lw=1)
        for y, (_, x, _) in enumerate(bars):
            ax.annotate(f"{x:.2f}x", (x, y), xytext=(3, 0), textcoords="offset points",
                        va="center", fontsize=8)  # fmt: skip
        ax.set_xlim(0, max(b[1] for b in bars) * 1.18)
        ax.set_xlabel(f"speed-up over the baseline ({mrays(base):.1f} Mrays/s)")
        ax.set_title(f"{g.title}", fontsize=11)
        ax.grid(axis="y", visible=False)
        ax.tick_params(axis="y", labelsize=8)
    fig.suptitle("Speed-up over the baseline configuration (grey; blue faster, red slower)")
    fig.tight_layout(rect=(0, 0, 1, 0.97))
    return fig


def _cost_axis(ax: Any, xs: list[float], unit: str) -> None:
    """Log-2 scale for wide ranges (SRAM in KiB: ticks 256, 512, 1,024), plain numbers."""
    lo, hi = min(xs), max(xs)
    if lo > 0 and hi / lo >= 8:
        ax.set_xscale("log", base=2)
    fmt = "{:,.0f}" if unit == "KiB" else "{:.3g}"
    ax.xaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: fmt.format(v)))
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    pad = (hi - lo) * 0.06 or hi * 0.05
    if ax.get_xscale() == "linear":
        ax.set_xlim(lo - pad, hi + pad)


def roofline(data: SweepData) -> Figure | None:
    """The roofline per scene and workload: every run a point at (DRAM bytes per ray, Mrays/s);
    the DRAM ceilings (peak bandwidth over bytes per ray: one line per distinct peak in the
    sweep) and, above each point, the lowest of its own config's other ceilings: pipelines,
    scheduler, L1 and L2 MSHRs by Little's law, L2 bandwidth (stats `roofline.ceilings`).
    A point on a line is bound by that resource; a point far below both is
    latency- or queue-bound (the verdict says which)."""
    groups = [g for g in data.groups() if any(_roof(r) for r in g.ok)][:4]
    if not groups:
        return None
    fig, axes = _panels(len(groups), 6.5, 4.6)
    for ax, g in zip(axes, groups, strict=True):
        runs = [r for r in g.ok if _roof(r) and _roof(r).get("dram_bytes_per_ray")]
        if not runs:
            ax.set_visible(False)
            continue
        xs = [float(_roof(r)["dram_bytes_per_ray"]) for r in runs]
        lo, hi = min(xs) / 2, max(xs) * 2
        peaks = sorted({float(_roof(r)["peak_dram_bytes_per_second"]) for r in runs})
        grid = [lo * (hi / lo) ** (i / 50) for i in range(51)]
        for peak, color in zip(peaks, _line_colors(len(peaks)), strict=True):
            ax.plot(
                grid,
                [peak / x / 1e6 for x in grid],
                color=color,
                linestyle="--",
                label=f"DRAM ceiling {peak / 1e9:g} GB/s",
            )
        compute = [
            min((v for k, v in _roof(r)["ceilings"].items() if k != "dram"), default=None)
            for r in runs
        ]
        ax.scatter(
            [x for x, c in zip(xs, compute, strict=True) if c],
            [c / 1e6 for c in compute if c],
            marker="_",
            s=160,
            color="#555555",
            label="its own lowest other ceiling (pipelines, scheduler, MSHRs, L2)",
        )
        ax.scatter(xs, [mrays(r) for r in runs], color="#C44E52", zorder=3, label="run")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlim(lo, hi)
        plain = matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:,.0f}" if v >= 1 else f"{v:.3g}")
        for axis, limits in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
            # A log axis spanning less than a decade gets one power-of-ten tick or none:
            # 1-2-5 steps (finer when the span is narrower) give it several.
            axis.set_major_locator(matplotlib.ticker.FixedLocator(log_ticks(*limits)))
            axis.set_major_formatter(plain)
            axis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_xlabel("DRAM bytes per ray")
        ax.set_ylabel("Mrays/s")
        ax.set_title(g.title)
    fig.tight_layout()
    _fig_legend(fig)  # below the panels: inside one it hid the runs at low bytes per ray
    return fig


def log_ticks(lo: float, hi: float, least: int = 3) -> list[float]:
    """Ticks for a log axis over [lo, hi]: 1-2-5 steps of each decade, finer steps (1, 1.5, 2,
    3, 4, 5, 7) when that leaves fewer than `least` inside, every tick inside the range."""
    if not (lo > 0 and hi > lo):
        return []
    ticks: list[float] = []
    for steps in ((1.0,), (1.0, 2.0, 5.0), (1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 7.0)):
        first, last = math.floor(math.log10(lo)), math.ceil(math.log10(hi))
        ticks = [s * 10.0**d for d in range(first, last + 1) for s in steps]
        ticks = [t for t in ticks if lo <= t <= hi]
        if len(ticks) >= least:
            return ticks
    if len(ticks) < 2:  # narrower than one 1.5x step: the ends and the geometric middle
        ticks = [float(f"{t:.2g}") for t in (lo, math.sqrt(lo * hi), hi)]
        ticks = [t for t in ticks if lo <= t <= hi] or [lo, hi]
    return ticks


def _roof(rec: RunRecord) -> dict[str, Any]:
    return (rec.stats or {}).get("roofline") or {}
