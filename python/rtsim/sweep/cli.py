"""`rtsim sweep`, `rtsim results` and `rtsim report` (registered on the rtsim command line).

rtsim sweep SPEC.yaml -o SWEEP [--scheduler tcp://HOST:PORT] [--workers N] [--timeout S]
rtsim results SWEEP [--csv [FILE]]
rtsim report SWEEP [-o report.html]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING

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
    from rtsim.sweep.results import Results, text_table

    results = Results(Path(args.sweep))
    config = bool(getattr(args, "config", False))
    wrote = False
    if getattr(args, "parquet", None):
        results.to_parquet(args.parquet, config=config)
        console.print(f"wrote {len(results)} runs to {args.parquet}", highlight=False)
        wrote = True
    if args.csv is not None:
        text = results.to_csv(config=config)
        if args.csv == "-":
            sys.stdout.write(text)
        else:
            Path(args.csv).write_text(text)
            console.print(f"wrote {len(results)} runs to {args.csv}", highlight=False)
        wrote = True
    if not wrote:
        # Plain text: every column under its full name, the same columns as to_pandas() and the
        # CSV, never cut and never coloured, whether on a terminal or through a pipe.
        cols, rows = results.rows(config)
        sys.stdout.write(text_table([c.name for c in cols], rows))
    return 0


def results_order(records: list[RunRecord], keys: list[str]) -> list[RunRecord]:
    """Runs in the table's order (rtsim/sweep/results.py)."""
    from rtsim.sweep.results import results_order as order

    return order(records, keys)


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
        help="a sweep's results: the tidy table as text, --csv or --parquet",
        description="Prints the tidy table of a sweep's runs (one row per run: the swept keys, "
        "the summary stats, DRAM bytes per ray by data kind, area, energy and SRAM; the columns "
        "of rtsim.open_results(SWEEP).to_pandas(), docs/sweeps.md) as plain aligned text, or "
        "writes it as CSV or Parquet.",
    )
    p.add_argument("sweep", metavar="SWEEP", help="sweep folder (holds results.sqlite)")
    p.add_argument(
        "--csv",
        nargs="?",
        const="-",
        default=None,
        metavar="FILE",
        help="write the table as CSV to FILE, or stdout if no FILE (default: print it as text)",
    )
    p.add_argument(
        "--parquet",
        default=None,
        metavar="FILE",
        help="write the table as Parquet to FILE (needs pyarrow: pip install 'rtsim[parquet]'; "
        "default: none)",
    )
    p.add_argument(
        "--config",
        action="store_true",
        help="add a column per config key (every key, not only the swept ones)",
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
