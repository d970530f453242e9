"""`rtsim simulate` and `rtsim config`: run rtsim-sim through the launcher (rtsim/launcher.py),
drive a progress bar from its JSON progress lines and print the run's summary.

rtsim simulate TRACE [--config CFG.json] [--set key=value ...] -o RUN [--timeline] [--timeout S]
               [--check-verdict]
rtsim config --defaults | --schema
rtsim capabilities [--json]

Kept light at import time (no numpy, no C++ extension): a short simulation should not wait for
Python start-up. rich is imported when a run starts.
"""

from __future__ import annotations

import argparse
import math
import subprocess
import sys
from pathlib import Path
from typing import Any

from rtsim.cli_help import HelpFormatter
from rtsim.launcher import EXIT_BAD_INPUT, EXIT_MISMATCH, EXIT_OK, SimJob, find_sim, run_sim

#: One line per fidelity level for `rtsim simulate --help` (docs/fidelity.md has the details;
#: tests check these are exactly the levels of the config tree).
FIDELITY_LEVELS = {
    "functional": "reference traversal, fetch and test counts, no time (fastest; hit check)",
    "analytic": "counts + functional caches + a closed-form roofline of pipelines and DRAM",
    "approx": "event-driven SystemC model of every block (the default)",
    "detailed": "approx + per-cycle arbitration, L2 MSHRs",
}


def simulate_epilog() -> str:
    levels = "\n".join(f"  {name:<11} {text}" for name, text in FIDELITY_LEVELS.items())
    return (
        "fidelity levels (--set fidelity=LEVEL; docs/fidelity.md):\n"
        f"{levels}\n\n"
        "Sampling: --set sampling.fraction=0.05 simulates a stratified 5% sample and reports the "
        "estimate with a 95% interval.\n\n"
        "Every config key with its default, unit, range and meaning (or docs/config.md):\n"
        "  rtsim config --schema\n"
        "From Python: rtsim.simulate(TRACE, l1__size_kib=32) (docs/python.md)."
    )


EXIT_TIMEOUT = 4


def positive_seconds(text: str) -> float:
    """An argparse type: a finite number of seconds > 0."""
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not (value > 0 and math.isfinite(value)):
        raise argparse.ArgumentTypeError(f"expected a number of seconds > 0, got '{text}'")
    return value


def run_and_report(
    job: SimJob, console: Any, show_progress: bool = True, timeout: float | None = None
) -> int:
    """Runs one simulation with a progress bar and prints its summary; returns the exit code."""
    from rich.console import Console

    from rtsim.sim_summary import print_mismatches, print_sim_summary

    err_console = Console(stderr=True)

    def echo(line: str) -> None:
        # Never wrapped: rtsim-sim's messages name files, and a path broken across lines (the
        # console breaks long words at its width) cannot be copied.
        err_console.print(line, markup=False, highlight=False, soft_wrap=True)

    job.progress = show_progress
    if show_progress:
        from rtsim.progress import TraceProgress

        with TraceProgress(console=err_console) as bar:
            result = run_sim(
                job,
                timeout=timeout,
                on_progress=lambda d, n: bar(d, n, "simulate"),
                on_message=echo,
                stdout=None,
            )
    else:
        result = run_sim(job, timeout=timeout, on_message=echo, stdout=None)
    if result.timed_out:
        print(
            f"rtsim: error: rtsim-sim timed out after {timeout:g} s and was killed (--timeout); "
            f"run folder {job.out_dir} has no stats",
            file=sys.stderr,
        )
        return EXIT_TIMEOUT
    if result.returncode == EXIT_BAD_INPUT:
        return EXIT_BAD_INPUT  # rtsim-sim's message (naming the file or field) was echoed
    if result.returncode not in (EXIT_OK, EXIT_MISMATCH) or result.stats is None:
        print(
            f"rtsim: error: {result.describe_failure()}; run folder {job.out_dir}", file=sys.stderr
        )
        return result.returncode if result.returncode > 0 else 1
    print_sim_summary(result.stats, console)
    console.print(f"run:      {job.out_dir}  (stats.json, config.resolved.json, provenance.json)")
    if job.timeline and (job.out_dir / "timeline.json").is_file():
        console.print(f"timeline: {job.out_dir / 'timeline.json'}  (open in ui.perfetto.dev)")
    if job.dram_trace and (job.out_dir / "dram_trace.dramsim3.txt").is_file():
        console.print(f"dram:     {job.out_dir / 'dram_trace.dramsim3.txt'}  (DRAMsim3 trace)")
    if result.returncode == EXIT_MISMATCH:
        print_mismatches(result.stats, err_console)
    return result.returncode


def config_file(config: str | None, out_dir: Path) -> Path | None:
    """--config as rtsim-sim takes it: a JSON file as given; a preset name ('rtx2060',
    'base+tu16', as Python's configs take them) composed and written to RUN/config.preset.json.
    An unknown name raises ConfigError listing the presets (exit 2)."""
    if config is None:
        return None
    path = Path(config)
    if path.exists() or config.endswith(".json") or "/" in config:
        return path
    from rtsim.config import compose

    composed = compose(config)
    out_dir.mkdir(parents=True, exist_ok=True)
    preset = out_dir / "config.preset.json"
    preset.write_text(composed.to_json())
    return preset


def cmd_simulate(args: argparse.Namespace, console: Any) -> int:
    from rtsim.errors import RtsimError

    try:
        config = config_file(args.config, Path(args.output))
    except RtsimError as err:
        print(f"rtsim: error: {err}", file=sys.stderr)
        return EXIT_BAD_INPUT
    job = SimJob(
        trace=Path(args.trace),
        out_dir=Path(args.output),
        config=config,
        sets=list(args.set or []),
        timeline=args.timeline,
        dram_trace=args.dram_trace,
        check_verdict=args.check_verdict,
    )
    return run_and_report(job, console, show_progress=not args.no_progress, timeout=args.timeout)


def cmd_config(args: argparse.Namespace, console: Any) -> int:
    flag = "--dump-schema" if args.schema else "--dump-defaults"
    result = subprocess.run([str(find_sim()), flag], capture_output=True, text=True, check=False)
    if result.returncode != 0:
        sys.stderr.write(result.stderr)
        return result.returncode if result.returncode > 0 else 1
    sys.stdout.write(result.stdout)
    return 0


def cmd_capabilities(args: argparse.Namespace, console: Any) -> int:
    flag = "--capabilities" if args.json else "--capabilities-markdown"
    result = subprocess.run([str(find_sim()), flag], capture_output=True, text=True, check=False)
    if result.returncode != 0:
        sys.stderr.write(result.stderr)
        return result.returncode if result.returncode > 0 else 1
    sys.stdout.write(result.stdout)
    return 0


def add_parsers(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    """Registers `simulate`, `config` and `capabilities` on the `rtsim` subcommand parser."""
    p = sub.add_parser(
        "simulate",
        formatter_class=HelpFormatter,
        help="replay a trace on the SystemC accelerator model (rtsim-sim) and summarise the run",
        description="Replays TRACE on the accelerator model (one rtsim-sim process), checks every "
        "hit against the reference and writes RUN/stats.json, RUN/config.resolved.json and "
        "RUN/provenance.json. Exit codes: 0 ok, 2 bad input, 3 simulated hits or work differ "
        "from the reference, 4 timed out (--timeout).",
        epilog=simulate_epilog(),
    )
    p.add_argument("trace", metavar="TRACE", help="trace folder (from rtsim trace) or .rtt file")
    p.add_argument(
        "--config",
        metavar="CFG.json",
        default=None,
        help="config JSON over the defaults, or a preset name such as rtx2060 or base+tu16 "
        "(default: the defaults, rtsim config --defaults)",
    )
    p.add_argument(
        "--set",
        action="append",
        metavar="KEY=VALUE",
        default=[],
        help="override one config key after --config, e.g. l1.size_kib=32 or fidelity=analytic "
        "(repeatable; default: none)",
    )
    p.add_argument("-o", "--output", required=True, metavar="RUN", help="run folder")
    p.add_argument(
        "--timeline", action="store_true", help="also write RUN/timeline.json (Perfetto)"
    )
    p.add_argument(
        "--dram-trace",
        action="store_true",
        help="also write the requests that reached DRAM (RUN/dram_trace.dramsim3.txt, "
        "dram_requests.csv, dram_trace.json) for DRAMsim3 or Ramulator 2 (approx, detailed)",
    )
    p.add_argument(
        "--timeout",
        type=positive_seconds,
        default=None,
        metavar="SECONDS",
        help="kill rtsim-sim after this many seconds and exit with status 4 (default: no limit)",
    )
    p.add_argument(
        "--check-verdict",
        action="store_true",
        help="after the run, re-run the verdict's top three knobs and its co-limit (each one "
        "rtsim-sim process, RUN/check/N) and print measured against estimated gains",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_simulate)

    p = sub.add_parser(
        "config",
        formatter_class=HelpFormatter,
        help="print the simulator's default config or its schema",
        description="Prints the simulator's config tree as JSON: its defaults, or every field "
        "with its default, unit, range and meaning.",
    )
    group = p.add_mutually_exclusive_group(required=True)
    group.add_argument("--defaults", action="store_true", help="the default config as JSON")
    group.add_argument(
        "--schema", action="store_true", help="every field: default, unit, range, doc (JSON)"
    )
    p.set_defaults(func=cmd_config)

    p = sub.add_parser(
        "capabilities",
        formatter_class=HelpFormatter,
        help="print what composes with what: structures, unit kinds, levels and every rule",
        description="Prints the table the run's one resolution step applies "
        "(docs/capabilities.md): what each acceleration structure offers, what each traversal "
        "unit kind needs, what each fidelity level costs, every rule that refuses a combination "
        "(why, and what to change), and the matrix of techniques x unit kinds x structures and "
        "x levels.",
    )
    p.add_argument("--json", action="store_true", help="as JSON (default: Markdown)")
    p.set_defaults(func=cmd_capabilities)
