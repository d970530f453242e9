"""`rtsim accuracy --spec SPEC.yaml`: each fidelity level's error and speed across a design grid.

Traces every scene and workload of a sweep spec once, runs every configuration of its grid at
each level (one rtsim-sim process per run, --no-verdict), and reports per trace and level the
error in cycles against `detailed` (median and max of |error|), the rank agreement of the
configurations (Kendall's tau-b over the points both levels ran, and the largest gap in
`detailed` between two configurations the level ranks the other way round), whether the level
picks the same best design and the same Pareto front of cycles against area, and the wall time
of the whole grid against detailed's (the sweep speed-up:
at the analytic level the first run per trace and key builds the per-trace analysis, the others
reuse it). The pseudo-level `analytic_functional` is the analytic level with functional caches
(analytic.caches=functional): the analytic level's hit rates are compared with it per cache
level. Writes DIR/grid.csv, DIR/grid.json, DIR/grid.md and DIR/grid.png; docs/fidelity.md
explains.
"""

from __future__ import annotations

import csv
import json
import statistics
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from rich.console import Console

from rtsim.launcher import SimJob, find_sim, run_sim
from rtsim.sweep.spec import RunPlan, load_spec
from rtsim.sweep.tasks import make_trace

REFERENCE = "detailed"
PSEUDO = {"analytic_functional": ("analytic", ["analytic.caches=functional"])}


@dataclass
class GridRow:
    """One run: a configuration of the grid at one level on one trace."""

    trace: str
    point: str  # the swept values, "key=value ..."
    level: str
    status: str = "ok"
    wall_seconds: float | None = None
    cycles: float | None = None
    error: float | None = None  # against the reference level's cycles at the same point
    l1_hit_rate: float | None = None
    l2_hit_rate: float | None = None
    dram_bytes: float | None = None
    area_mm2: float | None = None
    analysis_reused: bool | None = None
    hit_mismatches: int | None = None


def kendall_tau(x: list[float], y: list[float]) -> float | None:
    """Kendall's tau-b of two rankings (ties count as neither concordant nor discordant)."""
    n = len(x)
    if n < 2:
        return None
    conc = disc = tx = ty = 0
    for i in range(n):
        for j in range(i + 1, n):
            dx, dy = x[i] - x[j], y[i] - y[j]
            if dx == 0 and dy == 0:
                continue
            if dx == 0:
                tx += 1
            elif dy == 0:
                ty += 1
            elif (dx > 0) == (dy > 0):
                conc += 1
            else:
                disc += 1
    denom = ((conc + disc + tx) * (conc + disc + ty)) ** 0.5
    return (conc - disc) / denom if denom else None


def largest_misordered_gap(x: list[float], y: list[float]) -> float:
    """The largest relative gap in x between two points that y ranks the other way round (0: none).

    Tau counts a swap of two designs 0.1% apart like one of two designs 2x apart; this says how
    far apart, in the reference, the designs a level misorders are."""
    gap = 0.0
    for i in range(len(x)):
        for j in range(i + 1, len(x)):
            if (x[i] - x[j]) * (y[i] - y[j]) < 0:
                gap = max(gap, abs(x[i] - x[j]) / min(x[i], x[j]))
    return gap


def pareto_front(points: dict[str, tuple[float, float]]) -> set[str]:
    """The points no other point beats on both cycles and area (lower is better on both)."""

    def beaten(p: tuple[float, float]) -> bool:
        return any(q[0] <= p[0] and q[1] <= p[1] and q != p for q in points.values())

    return {name for name, p in points.items() if not beaten(p)}


def point_label(run: RunPlan) -> str:
    return " ".join(f"{k}={v}" for k, v in run.params.items())


def run_level(
    exe: Path, trace: Path, run: RunPlan, level: str, folder: Path, sets: list[str] | None = None
) -> GridRow:
    row = GridRow(trace.name, point_label(run), level)
    fidelity, extra = PSEUDO.get(level, (level, []))
    folder.mkdir(parents=True, exist_ok=True)
    config = run.config.to_dict()
    (folder / "config.json").write_text(json.dumps(config))
    # The user's overrides (--set) apply to every run; the level's own settings after them.
    job = SimJob(
        trace=trace,
        out_dir=folder,
        config=folder / "config.json",
        sets=[*(sets or []), f"fidelity={fidelity}", *extra],
        verdict=False,
    )
    result = run_sim(job, exe=exe)
    row.wall_seconds = result.wall_seconds
    if result.returncode not in (0, 3) or result.stats is None:
        lines = result.messages
        row.status = (lines[-1] if lines else result.describe_failure()).replace(
            "rtsim-sim: error: ", ""
        )
        row.wall_seconds = None
        return row
    stats = result.stats
    s = stats["summary"]
    row.cycles, row.hit_mismatches = s.get("cycles"), s.get("hit_mismatches")
    row.l1_hit_rate, row.l2_hit_rate, row.dram_bytes, row.area_mm2 = (
        s.get("l1_hit_rate"),
        s.get("l2_hit_rate"),
        s.get("dram_bytes"),
        s.get("area_mm2"),
    )
    analysis = stats.get("model", {}).get("analytic", {}).get("analysis")
    row.analysis_reused = analysis.get("reused") if analysis else None
    return row


def trace_of(run: RunPlan, out: Path) -> Path:
    from rtsim.sweep.runner import trace_task

    plan = run.trace
    task = trace_task(plan, out)
    result = make_trace(task)
    if not result.get("ok"):
        raise RuntimeError(f"tracing {plan.folder_name} failed: {result.get('error')}")
    return Path(task.trace_dir)


def run_grid(
    spec_path: Path,
    out: Path,
    levels: list[str],
    console: Console,
    sets: list[str] | None = None,
) -> list[GridRow]:
    """Runs every point of the spec's grid at each level; `sets` (KEY=VALUE) override every run."""
    exe = find_sim()
    spec = load_spec(spec_path)
    rows: list[GridRow] = []
    runs = spec.runs()
    console.print(f"grid {spec.name}: {len(runs)} runs x levels {', '.join(levels)}")
    for run in runs:
        trace = trace_of(run, out.resolve())
        for level in levels:
            folder = out / "runs" / trace.name / run.run_id[:12] / level
            row = run_level(exe, trace, run, level, folder, sets)
            rows.append(row)
            what = (
                f"{row.wall_seconds:7.2f} s  cycles {row.cycles}"
                if row.status == "ok"
                else row.status
            )
            console.print(f"  {trace.name:<28} {level:<20} {row.point:<60} {what}", highlight=False)
    compare(rows)
    write_grid(rows, out)
    return rows


def compare(rows: list[GridRow]) -> None:
    ref = {(r.trace, r.point): r for r in rows if r.level == REFERENCE and r.cycles}
    for r in rows:
        base = ref.get((r.trace, r.point))
        if base and r.cycles and base.cycles:
            r.error = (r.cycles - base.cycles) / base.cycles


def summarize_grid(rows: list[GridRow]) -> list[dict[str, Any]]:
    """Per trace and level: error spread, Kendall tau, best design, wall times, hit-rate errors."""
    out = []
    traces = sorted({r.trace for r in rows})
    levels = list(dict.fromkeys(r.level for r in rows))
    for trace in traces:
        ref = {r.point: r for r in rows if r.trace == trace and r.level == REFERENCE and r.cycles}
        exact = {r.point: r for r in rows if r.trace == trace and r.level == "analytic_functional"}
        for level in levels:
            mine = [r for r in rows if r.trace == trace and r.level == level and r.cycles]
            both = [r for r in mine if r.point in ref]
            errors = [abs(r.error) for r in both if r.error is not None]
            ref_cycles = [ref[r.point].cycles for r in both]
            level_cycles = [r.cycles for r in both]
            tau = kendall_tau(ref_cycles, level_cycles)  # type: ignore[arg-type]
            gap = largest_misordered_gap(ref_cycles, level_cycles)  # type: ignore[arg-type]
            front = same_front(both, ref)
            best = min(both, key=lambda r: r.cycles).point if both else None  # type: ignore[arg-type,return-value]
            best_ref = (
                min((ref[r.point] for r in both), key=lambda r: r.cycles).point if both else None
            )  # type: ignore[arg-type,return-value]
            wall = sum(r.wall_seconds or 0 for r in both)
            ref_wall = sum(ref[r.point].wall_seconds or 0 for r in both)
            row: dict[str, Any] = {
                "trace": trace,
                "level": level,
                "points": len(both),
                "skipped": len(
                    [r for r in rows if r.trace == trace and r.level == level and r.status != "ok"]
                ),
                "median_abs_error": statistics.median(errors) if errors else None,
                "max_abs_error": max(errors) if errors else None,
                "kendall_tau": tau,
                "largest_misordered_gap": gap if both else None,
                "same_pareto_front": front,
                "same_best": best == best_ref if both else None,
                "wall_seconds": wall,
                "speedup": ref_wall / wall if wall > 0 else None,
            }
            if level == "analytic" and exact:
                for key in ("l1_hit_rate", "l2_hit_rate"):
                    diffs = [
                        abs((r.__dict__[key] or 0) - (exact[r.point].__dict__[key] or 0))
                        for r in mine
                        if r.point in exact and exact[r.point].cycles
                    ]
                    row[f"{key}_error_max"] = max(diffs) if diffs else None
                    row[f"{key}_error_median"] = statistics.median(diffs) if diffs else None
            out.append(row)
    return out


def same_front(mine: list[GridRow], ref: dict[str, GridRow]) -> bool | None:
    """Whether the level's Pareto front (cycles against area) is the reference's; None: no area."""
    if not mine or any(r.area_mm2 is None or ref[r.point].area_mm2 is None for r in mine):
        return None
    front = pareto_front({r.point: (r.cycles, r.area_mm2) for r in mine})  # type: ignore[misc]
    ref_front = pareto_front({r.point: (ref[r.point].cycles, ref[r.point].area_mm2) for r in mine})  # type: ignore[misc]
    return front == ref_front


def yes_no(x: bool | None) -> str:
    return "" if x is None else ("yes" if x else "no")


def fmt(x: float | None, pct: bool = False, digits: int = 1) -> str:
    if x is None:
        return ""
    return f"{100 * x:.{digits}f}%" if pct else f"{x:.{digits}f}"


def _median_max(s: dict[str, Any], key: str) -> str:
    return f"{fmt(s[key + '_median'], True, 2)} / {fmt(s[key + '_max'], True, 2)}"


def markdown(summary: list[dict[str, Any]]) -> str:
    lines = [
        "| trace | level | configs | median abs error | max abs error | Kendall tau "
        "| largest misordered gap | same best | same Pareto front (cycles, area) "
        "| grid wall (s) | speed-up vs detailed | L1 hit-rate error (median / max) "
        "| L2 hit-rate error |",
        "|" + "---|" * 13,
    ]
    for s in summary:
        hr = ""
        if s.get("l1_hit_rate_error_max") is not None:
            hr = _median_max(s, "l1_hit_rate_error")
        hr2 = ""
        if s.get("l2_hit_rate_error_max") is not None:
            hr2 = _median_max(s, "l2_hit_rate_error")
        skipped = f" (+{s['skipped']} n/a)" if s["skipped"] else ""
        lines.append(
            f"| {s['trace']} | {s['level']} | {s['points']}{skipped} "
            f"| {fmt(s['median_abs_error'], True)} "
            f"| {fmt(s['max_abs_error'], True)} | {fmt(s['kendall_tau'], digits=2)} "
            f"| {fmt(s['largest_misordered_gap'], True, 2)} "
            f"| {yes_no(s['same_best'])} | {yes_no(s['same_pareto_front'])} "
            f"| {fmt(s['wall_seconds'], digits=2)} | {fmt(s['speedup'])}x | {hr} | {hr2} |"
        )
    return "\n".join(lines) + "\n"


def _named_point(point: str) -> str:
    """The `point` label of a run of a spec with named points, else its swept values."""
    for token in point.split():
        if token.startswith("point="):
            return token.removeprefix("point=")
    return point


def by_point_markdown(rows: list[GridRow]) -> str:
    """Per level and named point (or swept values): the error against detailed over every trace
    and grid value the point ran at."""
    groups: dict[tuple[str, str], list[float]] = {}
    order: list[tuple[str, str]] = []
    for r in rows:
        if r.level == REFERENCE or r.error is None:
            continue
        key = (r.level, _named_point(r.point))
        if key not in groups:
            groups[key] = []
            order.append(key)
        groups[key].append(r.error)
    lines = [
        "| level | point | runs | median error | min / max error | max abs error |",
        "|---|---|---:|---:|---:|---:|",
    ]
    for key in sorted(order, key=lambda k: (k[0], order.index(k))):
        errs = groups[key]
        lines.append(
            f"| {key[0]} | {key[1]} | {len(errs)} | {100 * statistics.median(errs):+.1f}% "
            f"| {100 * min(errs):+.1f}% / {100 * max(errs):+.1f}% "
            f"| {100 * max(abs(e) for e in errs):.1f}% |"
        )
    return "\n".join(lines) + "\n"


def write_grid(rows: list[GridRow], out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    summary = summarize_grid(rows)
    (out / "grid.json").write_text(
        json.dumps({"runs": [asdict(r) for r in rows], "summary": summary}, indent=2)
    )
    with (out / "grid.csv").open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(asdict(rows[0]))) if rows else None
        if w:
            w.writeheader()
            for r in rows:
                w.writerow(asdict(r))
    (out / "grid.md").write_text(markdown(summary) + "\n" + by_point_markdown(rows))
    plot_grid(rows, out / "grid.png")


def plot_grid(rows: list[GridRow], path: Path) -> None:
    """Each configuration's error against detailed (left) and its rank by cycles at the level
    against its rank at detailed (right), one colour per level and one marker per trace."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ref = {(r.trace, r.point): r.cycles for r in rows if r.level == REFERENCE and r.cycles}
    levels = [lvl for lvl in dict.fromkeys(r.level for r in rows) if lvl != REFERENCE]
    traces = sorted({r.trace for r in rows})
    markers = {t: "osD^vP*X"[i % 8] for i, t in enumerate(traces)}
    colors = {"analytic": "#2ca02c", "approx": "#1f77b4", "analytic_functional": "#9467bd"}
    fig, (err_ax, rank_ax) = plt.subplots(1, 2, figsize=(12, 6.2))
    for level in levels:
        for trace in traces:
            mine = [
                r
                for r in rows
                if r.level == level and r.trace == trace and r.cycles and (trace, r.point) in ref
            ]
            if not mine:
                continue
            xs = [ref[(trace, r.point)] for r in mine]
            errs = [100 * (r.cycles - x) / x for r, x in zip(mine, xs, strict=True)]  # type: ignore[operator]
            style = {"color": colors.get(level), "marker": markers[trace], "alpha": 0.8, "s": 26}
            err_ax.scatter(xs, errs, label=f"{level}, {trace.split('-bvh')[0]}", **style)  # type: ignore[arg-type]
            order_ref = sorted(range(len(mine)), key=lambda i: xs[i])
            order_lvl = sorted(range(len(mine)), key=lambda i: mine[i].cycles)  # type: ignore[arg-type,return-value]
            rank_ref = {i: k for k, i in enumerate(order_ref)}
            rank_lvl = {i: k for k, i in enumerate(order_lvl)}
            rank_ax.scatter(
                [rank_ref[i] + 1 for i in range(len(mine))],
                [rank_lvl[i] + 1 for i in range(len(mine))],
                **style,  # type: ignore[arg-type]
            )
    for band, style in ((0, "-"), (5, "--"), (-5, "--"), (15, ":"), (-15, ":")):
        err_ax.axhline(band, color="#999999", ls=style, lw=0.8)
    err_ax.set_xscale("log")
    err_ax.set_xlabel("detailed cycles (one point per configuration and trace)")
    err_ax.set_ylabel("error against detailed, % (dashed: 5%, dotted: 15%)")
    err_ax.set_title("Error of each configuration", fontsize=11)
    fig.legend(fontsize=8, ncol=4, loc="lower center", frameon=False)
    err_ax.grid(True, which="both", alpha=0.25)
    top = max(
        (len([r for r in rows if r.level == REFERENCE and r.trace == t]) for t in traces), default=1
    )
    rank_ax.plot([1, top], [1, top], color="#999999", lw=0.8)
    rank_ax.set_xlabel("rank at detailed (1: fastest configuration of its trace)")
    rank_ax.set_ylabel("rank at the level")
    rank_ax.set_title("Does the level order the designs as detailed does?", fontsize=11)
    rank_ax.grid(True, alpha=0.25)
    fig.tight_layout(rect=(0, 0.13, 1, 1))  # room for the legend below
    fig.savefig(path, dpi=80)
    plt.close(fig)
