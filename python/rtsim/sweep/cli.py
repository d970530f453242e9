"""`rtsim sweep`, `rtsim results` and `rtsim report` (registered on the rtsim command line).

rtsim sweep SPEC.yaml -o SWEEP [--scheduler tcp://HOST:PORT] [--workers N] [--timeout S]
rtsim results SWEEP [--csv [FILE]]
rtsim report SWEEP [-o report.html]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rtsim.cli_help import HelpFormatter

# Only the parsers are built at import time (every `rtsim` command builds them): the sweep
# machinery (Dask, numpy, yaml, rich) is imported by the commands that use it.
if TYPE_CHECKING:
    from rich.console import Console

    from rtsim.sweep.runner import SweepOutcome
    from rtsim.sweep.store import RunRecord


def print_outcome(outcome: SweepOutcome, out: Path, console: Console) -> None:
    console.print(
        f"sweep: {outcome.total} runs: {outcome.skipped} already done, {outcome.ok} ok, "
        f"{outcome.mismatch} hit mismatches, {outcome.failed} failed "
        f"in {outcome.wall_seconds:.1f} s -> {out / 'results.sqlite'}"
    )
    for name, error in outcome.failures[:10]:
        first = error.splitlines()[0] if error else ""
        console.print(f"  [red]failed[/] {name}: {first}", highlight=False)
    if len(outcome.failures) > 10:
        console.print(f"  ... and {len(outcome.failures) - 10} more (rtsim results {out})")


def cmd_sweep(args: argparse.Namespace, console: Console) -> int:
    from rtsim.args import check_utf8_path
    from rtsim.sweep.runner import SweepOptions, run_sweep
    from rtsim.sweep.spec import SpecError, load_spec

    check_utf8_path(args.output, "-o")  # every run's folder is under it, named in JSON
    try:
        spec = load_spec(Path(args.spec))
    except SpecError as err:
        print(f"rtsim: error: {err}", file=sys.stderr)
        return 2
    opts = SweepOptions(
        out_dir=Path(args.output),
        scheduler=args.scheduler,
        workers=args.workers,
        timeout=args.timeout,
        retry_failed=args.retry_failed,
        progress=not args.no_progress,
    )
    outcome = run_sweep(spec, opts, console)
    print_outcome(outcome, opts.out_dir, console)
    if args.check_front:
        print_front_check(opts.out_dir, args, console)
    return 0 if outcome.failed == 0 and outcome.mismatch == 0 else 1


def print_front_check(out: Path, args: argparse.Namespace, console: Console) -> None:
    """Re-runs the front designs' verdicts and prints estimated against measured gains."""
    import os

    from rich.table import Table

    from rtsim.sweep.front_check import check_front, pct

    workers = args.workers or os.cpu_count() or 1
    rows = check_front(out, workers=workers, timeout=args.timeout)
    table = Table(title="Pareto front: the verdict's knob, estimated against measured")
    for col in ("design", "named knob", "estimated", "measured", "best measured"):
        table.add_column(col)
    for r in rows:
        design = f"{r['scene']} {r['workload']} {r['accel']} " + " ".join(
            f"{k}={v}" for k, v in r["params"].items() if k != "accel"
        )
        if "error" in r:
            table.add_row(design, r["error"], "", "", "")
            continue
        best = f"{r['best']} {pct(r['best_measured'])}"
        table.add_row(design, r["named"], pct(r["estimated"]), pct(r["measured"]), best)
    console.print(table)
    console.print(f"front check: {len(rows)} designs -> {out / 'front_check.json'}")


def cmd_results(args: argparse.Namespace, console: Console) -> int:
    from rich.table import Table

    from rtsim.sweep.results import tidy_rows, to_csv
    from rtsim.sweep.store import open_store

    with open_store(Path(args.sweep), readonly=True) as store:
        records = list(store.runs())
    if args.csv is not None:
        text = to_csv(tidy_rows(records))
        if args.csv == "-":
            sys.stdout.write(text)
        else:
            Path(args.csv).write_text(text)
            console.print(f"wrote {len(records)} runs to {args.csv}")
        return 0
    keys = list(dict.fromkeys(k for r in records for k in r.params))
    table = Table(title=f"{args.sweep}: {len(records)} runs")
    for col in ("scene", "workload", *keys, "status", "Mrays/s", "DRAM B/ray", "wall s"):
        # Headers are never cut: a column is at least as wide as its name (the table wraps the
        # cells, not the key names a reader needs to tell the columns apart).
        table.add_column(
            col,
            justify="left" if col in ("scene", "workload", "status") else "right",
            min_width=len(col),
            no_wrap=True,
        )
    for r in results_order(records, keys):
        s = r.summary
        table.add_row(
            r.scene,
            r.workload,
            *(_key_cell(r, k) for k in keys),
            r.status if r.status == "ok" else f"[red]{r.status}[/]",
            f"{s['mrays_per_second']:.1f}" if s.get("mrays_per_second") is not None else "-",
            f"{s['dram_bytes_per_ray']:.0f}" if s.get("dram_bytes_per_ray") is not None else "-",
            f"{r.wall_seconds:.2f}" if r.wall_seconds is not None else "-",
        )
    # Wider than the terminal: print the table whole (the terminal wraps long lines) rather
    # than cutting its headers or its last columns.
    columns = ("scene", "workload", *keys, "status", "Mrays/s", "DRAM B/ray", "wall s")
    wide = sum(len(c) + 3 for c in columns) + 1
    console.print(table, width=max(console.width, wide), crop=False)
    return 0


def results_order(records: list[RunRecord], keys: list[str]) -> list[RunRecord]:
    """Runs in a stable, readable order: by scene, workload, then each swept key's value
    (numbers by value, 2 before 16; text by name), never the order they happened to finish."""
    from rtsim.sweep.results import key_value

    def rank(value: Any) -> tuple[int, float, str]:
        if isinstance(value, bool) or value is None:
            return (2, 0.0, str(value))
        if isinstance(value, int | float):
            return (0, float(value), "")
        return (1, 0.0, str(value))

    return sorted(
        records,
        key=lambda r: (r.scene, r.workload, *(rank(key_value(r, k)[0]) for k in keys)),
    )


def _key_cell(rec: RunRecord, key: str) -> str:
    """The run's value of a swept key; dimmed when the run's spec did not sweep it (a store
    mixing two specs), so no column is ever blank."""
    from rtsim.sweep.results import key_value

    value, swept = key_value(rec, key)
    text = "-" if value is None else str(value)
    return text if swept else f"[dim]{text}[/]"


def cmd_report(args: argparse.Namespace, console: Console) -> int:
    from rtsim.report import write_report

    out = Path(args.output) if args.output else Path(args.sweep) / "report.html"
    write_report(Path(args.sweep), out)
    console.print(f"report: {out}")
    return 0


def add_parsers(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    """Registers `sweep`, `results` and `report` on the `rtsim` subcommand parser."""
    p = sub.add_parser(
        "sweep",
        formatter_class=HelpFormatter,
        help="run a design-space sweep (scenes x workloads x configs) on Dask",
        description="Runs every scene x workload x config point of SPEC (docs/sweeps.md), one "
        "rtsim-sim process per run, into SWEEP/results.sqlite. Re-running resumes: finished runs "
        "are skipped. Exit 0 when every run is ok, 1 if any failed, 2 for a bad spec.",
    )
    p.add_argument("spec", metavar="SPEC.yaml", help="the sweep spec (docs/sweeps.md)")
    p.add_argument("-o", "--output", required=True, metavar="SWEEP", help="sweep folder")
    p.add_argument(
        "--scheduler",
        metavar="tcp://HOST:PORT",
        default=None,
        help="an existing Dask scheduler (default: a local cluster)",
    )
    p.add_argument(
        "--workers",
        type=int,
        default=0,
        metavar="N",
        help="local cluster worker processes (default: one per core)",
    )
    p.add_argument(
        "--timeout",
        type=float,
        default=None,
        metavar="SECONDS",
        help="per-run time limit (default: the spec's timeout, else 3600)",
    )
    p.add_argument("--retry-failed", action="store_true", help="re-run runs recorded as failed")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument(
        "--check-front",
        action="store_true",
        help="then re-run each Pareto-front design's verdict (rtsim-sim --check-verdict): the "
        "named knob's estimated against measured gain, and the best measured one "
        "(SWEEP/front_check.json)",
    )
    p.set_defaults(func=cmd_sweep)

    p = sub.add_parser(
        "results",
        formatter_class=HelpFormatter,
        help="a sweep's results: a summary table, or --csv",
        description="Prints a summary table of a sweep's runs, or writes the tidy table (one "
        "row per run: config keys and summary stats) as CSV.",
    )
    p.add_argument("sweep", metavar="SWEEP", help="sweep folder (holds results.sqlite)")
    p.add_argument(
        "--csv",
        nargs="?",
        const="-",
        default=None,
        metavar="FILE",
        help="write the tidy table (one row per run) as CSV to FILE, or stdout if no FILE "
        "(default: print the summary table instead)",
    )
    p.set_defaults(func=cmd_results)

    p = sub.add_parser(
        "report",
        formatter_class=HelpFormatter,
        help="write a sweep's HTML report (figures embedded)",
        description="Writes one self-contained HTML page from a sweep's results store.",
    )
    p.add_argument("sweep", metavar="SWEEP", help="sweep folder (holds results.sqlite)")
    p.add_argument(
        "-o",
        "--output",
        default=None,
        metavar="report.html",
        help="the HTML file to write (default: SWEEP/report.html)",
    )
    p.set_defaults(func=cmd_report)
