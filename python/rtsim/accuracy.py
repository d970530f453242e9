"""`rtsim accuracy`: what each fidelity level and sample size costs in accuracy and saves in time.

rtsim accuracy SCENE... [-o DIR] [--resolution WxH] [--fractions 0.01,0.05,0.1] [--repeat 3]
rtsim accuracy --spec SPEC.yaml [-o DIR] [--levels analytic,approx,detailed]   (accuracy_grid.py)

Per scene and workload (coherent primary rays, incoherent diffuse rays) it traces once, then runs
every level the installed rtsim-sim accepts (functional, analytic, approx, detailed) on that trace
and config, and each timed SystemC level again with sampling at a few fractions. Wall time is the
median over --repeat runs of the whole rtsim-sim process; the error is in cycles relative to the
reference level (`detailed`, or `approx` while rtsim-sim has no detailed level). A sampled run is
also compared with the full run of its own level (the sampling error) and its 95% interval is
checked for containing that full run. Writes DIR/accuracy.csv, DIR/accuracy.md,
DIR/accuracy.json and DIR/accuracy.png (wall time against |error|). docs/fidelity.md explains.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rtsim.cli_help import HelpFormatter
from rtsim.launcher import SimJob, find_sim, run_sim
from rtsim.scenes import resolve_scene

if TYPE_CHECKING:
    from rich.console import Console

LEVEL_ORDER = ("functional", "analytic", "approx", "detailed")
SAMPLED_LEVELS = ("approx", "detailed")  # sampling needs the SystemC model (sim/config validate)
WORKLOADS = {"primary": ["primary"], "diffuse": ["diffuse"]}
DEFAULT_FRACTIONS = (0.01, 0.05, 0.1)


@dataclass
class Row:
    """One line of the accuracy table: one level (and sample fraction) on one trace."""

    scene: str
    workload: str
    rays: int
    level: str
    fraction: float | None  # None: the full run
    status: str = "ok"  # ok, or why the run has no numbers (e.g. sample too small)
    wall_seconds: float | None = None  # median over repeats
    wall_seconds_runs: list[float] = field(default_factory=list)
    cycles: float | None = None
    cycles_ci95: tuple[float, float] | None = None
    reference: str = ""  # the level errors are relative to
    error: float | None = None  # (cycles - reference cycles) / reference cycles
    speedup: float | None = None  # reference wall time / this wall time
    sampling_error: float | None = None  # sampled only: against the full run of the same level
    ci_contains_full: bool | None = None
    sampling_speedup: float | None = None  # sampled only: full run's wall / this wall
    simulated_rays: int | None = None
    hit_mismatches: int | None = None

    @property
    def label(self) -> str:
        return self.level if self.fraction is None else f"{self.level} {self.fraction:.3g}"


def sim_levels(exe: Path) -> list[str]:
    """The fidelity levels this rtsim-sim accepts, in LEVEL_ORDER."""
    out = subprocess.run([str(exe), "--dump-schema"], capture_output=True, text=True, check=True)
    choices = json.loads(out.stdout)["fidelity"]["choices"]
    return [level for level in LEVEL_ORDER if level in choices]


def trace_workload(scene: str, workload: str, size: tuple[int, int], out: Path) -> Path:
    """Traces SCENE with one workload into OUT (reused when OUT already holds this trace)."""
    from rtsim import _core  # the C++ tracer; imported here so --help works without it

    manifest = out / "manifest.json"
    if manifest.is_file() and (out / "trace.rtt").is_file():
        m = json.loads(manifest.read_text())
        if m.get("accuracy_key") == [scene, workload, *size]:
            return out
    _core.trace_scene(
        resolve_scene(scene),
        out,
        workload=WORKLOADS[workload],
        width=size[0],
        height=size[1],
        bounces=1,
    )
    m = json.loads(manifest.read_text())
    m["accuracy_key"] = [scene, workload, *size]
    manifest.write_text(json.dumps(m, indent=2))
    return out


def run_once(
    exe: Path, trace: Path, run: Path, sets: list[str]
) -> tuple[float, int, dict[str, Any] | None, str]:
    """One rtsim-sim process: (wall seconds, exit code, stats or None, last stderr line)."""
    result = run_sim(SimJob(trace=trace, out_dir=run, sets=list(sets)), exe=exe)
    messages = result.messages
    return result.wall_seconds, result.returncode, result.stats, messages[-1] if messages else ""


def measure(exe: Path, trace: Path, run: Path, sets: list[str], repeat: int, row: Row) -> Row:
    import statistics  # here, not at the top: `rtsim --help` imports this module

    walls = []
    for _ in range(repeat):
        wall, code, stats, message = run_once(exe, trace, run, sets)
        if code not in (0, 3) or stats is None:
            text = message.replace("rtsim-sim: error: ", "").replace("config: ", "")
            row.status = text.split(";")[0]  # the reason, without the advice
            return row
        walls.append(wall)
    assert stats is not None
    summary = stats["summary"]
    row.wall_seconds, row.wall_seconds_runs = statistics.median(walls), walls
    row.cycles = summary.get("cycles")
    row.hit_mismatches = summary.get("hit_mismatches")
    if summary.get("sampled"):
        row.cycles_ci95 = tuple(summary["cycles_ci95"])  # type: ignore[assignment]
        row.simulated_rays = stats["sampling"]["simulated_rays"]
    else:
        row.simulated_rays = summary.get("rays")
    return row


def compare(rows: list[Row]) -> None:
    """Fills error and speed-up against the reference level, and sampling error against the full
    run of the same level, for the rows of one trace."""
    full = {r.level: r for r in rows if r.fraction is None and r.status == "ok"}
    timed = [lvl for lvl in ("detailed", "approx") if lvl in full and full[lvl].cycles]
    if not timed:
        return
    ref = full[timed[0]]
    for r in rows:
        r.reference = ref.level
        if r.status != "ok":
            continue
        if r.wall_seconds and ref.wall_seconds:
            r.speedup = ref.wall_seconds / r.wall_seconds
        if r.cycles and ref.cycles:
            r.error = (r.cycles - ref.cycles) / ref.cycles
        own = full.get(r.level)
        if r.fraction is not None and own is not None and own.cycles and r.cycles:
            r.sampling_error = (r.cycles - own.cycles) / own.cycles
            if own.wall_seconds and r.wall_seconds:
                r.sampling_speedup = own.wall_seconds / r.wall_seconds
            if r.cycles_ci95 is not None:
                r.ci_contains_full = r.cycles_ci95[0] <= own.cycles <= r.cycles_ci95[1]


def run_accuracy(
    scenes: list[str],
    out: Path,
    size: tuple[int, int],
    fractions: list[float],
    repeat: int,
    sets: list[str],
    workloads: list[str],
    console: Console,
) -> list[Row]:
    exe = find_sim()
    levels = sim_levels(exe)
    console.print(f"levels: {', '.join(levels)}; fractions: {', '.join(map(str, fractions))}")
    rows: list[Row] = []
    for scene in scenes:
        name = Path(scene).stem if Path(scene).suffix else scene
        for workload in workloads:
            tag = f"{name}-{workload}"
            trace = trace_workload(scene, workload, size, out / "traces" / tag)
            rays = int(json.loads((trace / "manifest.json").read_text()).get("rays", 0) or 0)
            group: list[Row] = []
            plan = [(lvl, None) for lvl in levels]
            plan += [(lvl, f) for lvl in levels if lvl in SAMPLED_LEVELS for f in fractions]
            for level, fraction in plan:
                row = Row(name, workload, rays, level, fraction)
                run_sets = [*sets, f"fidelity={level}"]
                if fraction is not None:
                    run_sets.append(f"sampling.fraction={fraction}")
                folder = (
                    out / "runs" / tag / (level if fraction is None else f"{level}-{fraction:g}")
                )
                measure(exe, trace, folder, run_sets, repeat, row)
                if not row.rays and row.simulated_rays and fraction is None:
                    row.rays = row.simulated_rays
                console.print(
                    f"  {tag:<24} {row.label:<16} "
                    + (
                        f"{row.wall_seconds:7.2f} s  cycles {row.cycles}"
                        if row.status == "ok"
                        else f"skipped: {row.status}"
                    ),
                    highlight=False,
                )
                group.append(row)
            for r in group:
                r.rays = r.rays or next((g.rays for g in group if g.rays), 0)
            compare(group)
            rows += group
    write_outputs(rows, out)
    return rows


def pct(x: float | None, digits: int = 2) -> str:
    return "" if x is None else f"{100 * x:+.{digits}f}%"


def fmt_speed(x: float | None) -> str:
    return "" if x is None else f"{x:.1f}x" if x < 100 else f"{x:.0f}x"


def write_outputs(rows: list[Row], out: Path) -> None:
    import csv

    out.mkdir(parents=True, exist_ok=True)
    (out / "accuracy.json").write_text(json.dumps([asdict(r) for r in rows], indent=2))
    columns = [
        "scene",
        "workload",
        "rays",
        "level",
        "fraction",
        "simulated_rays",
        "status",
        "wall_seconds",
        "cycles",
        "cycles_ci95",
        "reference",
        "error",
        "speedup",
        "sampling_error",
        "sampling_speedup",
        "ci_contains_full",
        "hit_mismatches",
    ]
    with (out / "accuracy.csv").open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(columns)
        for r in rows:
            d = asdict(r)
            w.writerow(["" if d[c] is None else d[c] for c in columns])
    (out / "accuracy.md").write_text(markdown_table(rows))
    plot(rows, out / "accuracy.png")


def markdown_table(rows: list[Row]) -> str:
    head = (
        "| scene | workload | level | rays simulated | wall (s) | speed-up vs ref | cycles "
        "| error vs ref | sampling error | 95% CI holds full |"
    )
    lines = [head, "|" + "---|" * 10]
    for r in rows:
        if r.status != "ok":
            lines.append(f"| {r.scene} | {r.workload} | {r.label} | | | | | | | {r.status} |")
            continue
        cycles = "" if r.cycles is None else f"{r.cycles:,.0f}"
        if r.cycles_ci95:
            cycles += f" ± {100 * (r.cycles_ci95[1] - r.cycles_ci95[0]) / 2 / (r.cycles or 1):.1f}%"
        ci = "" if r.ci_contains_full is None else ("yes" if r.ci_contains_full else "no")
        ref = " (ref)" if r.level == r.reference and r.fraction is None else ""
        speed = fmt_speed(r.sampling_speedup if r.fraction is not None else r.speedup)
        if r.fraction is not None and speed:
            speed += " vs full"
        lines.append(
            f"| {r.scene} | {r.workload} | {r.label}{ref} | {r.simulated_rays or 0:,} | "
            f"{r.wall_seconds:.3f} | {speed} | {cycles} | {pct(r.error)} | "
            f"{pct(r.sampling_error)} | {ci} |"
        )
    return "\n".join(lines) + "\n"


def plot(rows: list[Row], path: Path) -> None:
    import matplotlib.pyplot as plt

    fig = accuracy_figure(rows)
    # bbox_inches="tight": whatever the panel count, nothing outside the axes is cut off.
    fig.savefig(path, dpi=72, bbox_inches="tight")
    plt.close(fig)


def accuracy_figure(rows: list[Row]) -> Any:
    """Wall time against |error| per scene and workload, one colour per level."""
    import matplotlib
    import matplotlib.ticker

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    groups: dict[tuple[str, str], list[Row]] = {}
    for r in rows:
        groups.setdefault((r.scene, r.workload), []).append(r)
    n = len(groups)
    cols = min(n, 2)
    nrows = math.ceil(n / cols)
    fig, axes = plt.subplots(nrows, cols, figsize=(6.2 * cols, 4.4 * nrows), squeeze=False)
    colors = {
        "functional": "#7f7f7f",
        "analytic": "#2ca02c",
        "approx": "#1f77b4",
        "detailed": "#d62728",
    }
    floor = 1e-3  # |error| below 0.1% is drawn at 0.1%
    for ax, ((scene, workload), group) in zip(axes.flat, groups.items(), strict=False):
        ok = [r for r in group if r.status == "ok" and r.wall_seconds]
        for r in ok:
            color = colors.get(r.level, "black")
            if r.error is None or (r.level == r.reference and r.fraction is None):
                kind = "reference" if r.error is not None else "no cycles"
                ax.axvline(
                    r.wall_seconds, color=color, ls="--" if r.error is not None else ":", lw=1.2
                )
                ax.annotate(
                    f"{r.level} ({kind})",
                    (r.wall_seconds, 1.0),
                    xycoords=("data", "axes fraction"),
                    rotation=90,
                    va="top",
                    ha="right",
                    fontsize=8,
                    color=color,
                )
                continue
            y = max(abs(r.error), floor) * 100
            marker = "o" if r.fraction is None else "^"
            ax.scatter([r.wall_seconds], [y], color=color, marker=marker, s=46, zorder=3)
            label = r.level if r.fraction is None else f"{100 * r.fraction:g}%"
            ax.annotate(
                label,
                (r.wall_seconds, y),
                textcoords="offset points",
                xytext=(5, 3),
                fontsize=8,
                color=color,
            )
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_ylim(floor * 100 / 1.5, 100)
        plain = matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}")
        ax.xaxis.set_major_formatter(plain)
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.yaxis.set_major_formatter(plain)
        ax.set_xlabel("wall time of one rtsim-sim run (s, log)")
        ax.set_ylabel("|error in cycles| vs reference (%, log)")
        rays = next((r.rays for r in group if r.rays), 0)
        ax.set_title(f"{scene}, {workload} rays ({rays:,})", fontsize=11)
        ax.grid(True, which="both", alpha=0.25)
        for y, text in ((5, "5%"), (15, "15%")):
            ax.axhline(y, color="#999999", lw=0.7, ls=":")
            ax.annotate(
                text,
                (0.0, y),
                xycoords=("axes fraction", "data"),
                ha="left",
                va="bottom",
                fontsize=7,
                color="#777777",
            )
    for ax in list(axes.flat)[n:]:
        ax.set_visible(False)
    handles = [
        plt.Line2D([], [], color=c, marker="o", ls="", label=lvl) for lvl, c in colors.items()
    ]
    handles += [plt.Line2D([], [], color="black", marker="^", ls="", label="sampled (% of rays)")]
    # One legend row under two panels; under one panel the five entries need two rows.
    ncol = len(handles) if cols > 1 else 3
    legend = fig.legend(handles=handles, loc="lower center", ncol=ncol, fontsize=9, frameon=False)
    fig.suptitle("Fidelity levels and sampling: wall time against error in cycles", fontsize=12)
    # Leave the legend's own height at the bottom (measured, so it fits at any size).
    fig.canvas.draw()
    height = legend.get_window_extent().height / fig.bbox.height
    fig.tight_layout(rect=(0, height + 0.01, 1, 0.97))
    return fig


def parse_fractions(text: str) -> list[float]:
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        values = []
    if not values or any(not 0 < v <= 1 for v in values):
        raise argparse.ArgumentTypeError(
            f"expected fractions in (0, 1] like 0.01,0.05, got '{text}'"
        )
    return values


def write_grid_docs(args: argparse.Namespace, text: str, grid: list[Any], seconds: float) -> None:
    """The grid's tables between the MARKER markers of docs/fidelity.md, with how they were made."""
    from rtsim.doc_markers import write_between

    doc = Path("docs") / "fidelity.md"
    if not doc.is_file():
        raise ValueError(f"--write-docs: {doc} not found (run from the repository root)")
    gits = sorted(
        {
            str(json.loads(f.read_text()).get("git"))
            for f in Path(args.output).glob("runs/**/provenance.json")
        }
    )
    mismatches = sum(r.hit_mismatches or 0 for r in grid)
    how = (
        f"Generated by `rtsim accuracy --spec {args.spec} --levels {args.levels}"
        f"{''.join(f' --set {kv}' for kv in args.set or [])} --write-docs "
        f"{args.write_docs}` (rtsim-sim git {', '.join(gits)}; {time.strftime('%Y-%m-%d')}; "
        f"{len(grid)} runs in {seconds:.0f} s wall on {os.cpu_count()} cores; "
        f"{mismatches} hit mismatches). Error = the level's cycles against `detailed`'s at the "
        "same point.\n\n"
    )
    write_between(doc, args.write_docs, how + text)


def cmd_accuracy(args: argparse.Namespace, console: Console) -> int:
    if args.spec:
        from rtsim.accuracy_grid import by_point_markdown, markdown, run_grid, summarize_grid

        t0 = time.monotonic()
        grid = run_grid(
            Path(args.spec), Path(args.output), args.levels.split(","), console, args.set
        )
        text = markdown(summarize_grid(grid)) + "\n" + by_point_markdown(grid)
        print(text)
        if args.write_docs:
            write_grid_docs(args, text, grid, time.monotonic() - t0)
        console.print(f"wrote {Path(args.output) / 'grid.csv'}, grid.md, grid.json, grid.png")
        return 3 if any(r.hit_mismatches for r in grid) else 0
    if not args.scenes:
        raise ValueError("name at least one SCENE, or a sweep spec with --spec")
    unknown = [w for w in args.workloads.split(",") if w not in WORKLOADS]
    if unknown:
        raise ValueError(f"unknown workload(s) {unknown}; choose from {', '.join(WORKLOADS)}")
    out = Path(args.output)
    rows = run_accuracy(
        args.scenes,
        out,
        args.resolution,
        args.fractions,
        args.repeat,
        args.set,
        args.workloads.split(","),
        console,
    )
    print(markdown_table(rows))
    console.print(f"wrote {out / 'accuracy.csv'}, accuracy.md, accuracy.json, accuracy.png")
    bad = [r for r in rows if r.hit_mismatches]
    return 3 if bad else 0


def add_parser(sub: argparse._SubParsersAction, parse_resolution: Any) -> None:  # type: ignore[type-arg]
    p = sub.add_parser(
        "accuracy",
        formatter_class=HelpFormatter,
        help="wall time against error of each fidelity level and sample size (table and plot)",
        description="Per scene and workload (coherent primary, incoherent diffuse rays): "
        "traces once, runs every fidelity level and each timed level on samples of a few "
        "fractions, and writes DIR/accuracy.csv, .md, .json and .png: the wall time against the "
        "error in cycles of each (docs/fidelity.md).",
    )
    p.add_argument("scenes", nargs="*", metavar="SCENE", help="built-in or shared scene, or glTF")
    p.add_argument(
        "--spec",
        metavar="SPEC.yaml",
        help="a sweep spec (e.g. python/rtsim/specs/demo.yaml): each level's error, rank "
        "agreement and speed-up across its grid instead (grid.md, grid.csv, grid.png; "
        "default: none, the SCENE table)",
    )
    p.add_argument(
        "--levels",
        default="analytic,analytic_functional,approx,detailed",
        metavar="L,L",
        help="with --spec: levels to run (analytic_functional: the analytic level with "
        "functional caches, for hit-rate errors; default: all four)",
    )
    p.add_argument(
        "-o",
        "--output",
        default="out/accuracy",
        metavar="DIR",
        help="folder for traces, runs, tables",
    )
    p.add_argument(
        "--resolution",
        type=parse_resolution,
        default=(256, 192),
        metavar="WxH",
        help="image size of each traced workload",
    )
    p.add_argument(
        "--fractions",
        type=parse_fractions,
        default=",".join(f"{f:g}" for f in DEFAULT_FRACTIONS),
        metavar="F,F,...",
        help="sample fractions for the timed levels",
    )
    p.add_argument("--repeat", type=int, default=3, metavar="N", help="runs per point (median)")
    p.add_argument(
        "--workloads",
        default="primary,diffuse",
        metavar="W,W",
        help="primary (coherent) and/or diffuse (incoherent)",
    )
    p.add_argument(
        "--write-docs",
        metavar="MARKER",
        help="with --spec: write the tables between MARKER's markers of docs/fidelity.md "
        "(default: none)",
    )
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="config override for every run (repeatable; default: none)",
    )
    p.set_defaults(func=cmd_accuracy)
