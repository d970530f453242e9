"""`rtsim simulate` and `rtsim config`: run the `rtsim-sim` executable (one simulation per process,
DESIGN rule 4), drive a progress bar from its JSON progress lines and print the run's summary.

rtsim simulate TRACE [--config CFG.json] [--set key=value ...] -o RUN [--timeline] [--timeout S]
rtsim config --defaults | --schema
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import sysconfig
import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rich.console import Console

from rtsim.progress import TraceProgress
from rtsim.sim_summary import print_mismatches, print_sim_summary

SIM_EXE = "rtsim-sim"
EXIT_OK, EXIT_BAD_INPUT, EXIT_MISMATCH, EXIT_TIMEOUT = 0, 2, 3, 4


class SimNotFoundError(OSError):
    """No rtsim-sim executable could be found."""


def find_sim() -> Path:
    """The rtsim-sim executable: $RTSIM_SIM, else on PATH, else in this Python's scripts folder
    (where `pip install .` puts it), else the build tree (build/py/sim/rtsim-sim)."""
    env = os.environ.get("RTSIM_SIM")
    if env:
        if not Path(env).is_file():
            raise SimNotFoundError(f"RTSIM_SIM={env} is not a file")
        return Path(env)
    candidates: list[Path] = []
    found = shutil.which(SIM_EXE)
    if found:
        candidates.append(Path(found))
    for scripts in (sysconfig.get_path("scripts"), str(Path(sys.executable).parent)):
        if scripts:
            candidates.append(Path(scripts) / SIM_EXE)
    repo = Path(__file__).resolve().parents[2]
    candidates += [repo / "build" / "py" / "sim" / SIM_EXE, Path.cwd() / "build/py/sim" / SIM_EXE]
    for path in candidates:
        if path.is_file() and os.access(path, os.X_OK):
            return path
    raise SimNotFoundError(
        f"{SIM_EXE} not found (looked on PATH, in {sysconfig.get_path('scripts')} and in "
        "build/py/sim); build and install it with `bash scripts/setup.sh`"
    )


@dataclass
class SimJob:
    """One `rtsim-sim` run: a trace, config overrides and the run folder."""

    trace: Path
    out_dir: Path
    config: Path | None = None
    sets: list[str] = field(default_factory=list)
    timeline: bool = False
    timeout: float | None = None  # seconds; rtsim-sim is killed after this

    def command(self, exe: Path) -> list[str]:
        cmd = [str(exe), str(self.trace), "-o", str(self.out_dir), "--progress"]
        if self.config is not None:
            cmd += ["--config", str(self.config)]
        for assignment in self.sets:
            cmd += ["--set", assignment]
        if self.timeline:
            cmd.append("--timeline")
        return cmd


@dataclass
class SimResult:
    """What a run returned: rtsim-sim's exit code, its messages and the stats (if written)."""

    returncode: int
    messages: list[str]
    stats: dict[str, Any] | None
    timed_out: bool = False


def parse_progress(line: str) -> tuple[int, int] | None:
    """(done, total) from a progress line `{"progress": done, "total": n}`, else None."""
    text = line.strip()
    if not text.startswith("{"):
        return None
    try:
        data = json.loads(text)
    except json.JSONDecodeError:
        return None
    if not isinstance(data, dict) or "progress" not in data:
        return None
    try:
        return int(data["progress"]), int(data.get("total", 0))
    except (TypeError, ValueError):
        return None


def read_stats(out_dir: Path) -> dict[str, Any] | None:
    path = out_dir / "stats.json"
    if not path.is_file():
        return None
    try:
        data = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError):
        return None
    return data if isinstance(data, dict) else None


def run_sim(job: SimJob, show_progress: bool = True, echo: bool = True) -> SimResult:
    """Runs rtsim-sim; progress lines drive a bar, other stderr lines are echoed to stderr."""
    exe = find_sim()
    if job.out_dir.exists() and not job.out_dir.is_dir():
        raise NotADirectoryError(f"{job.out_dir}: the run folder is a file")
    # A stale stats.json must never pass for this run's.
    stale = job.out_dir / "stats.json"
    if stale.is_file():
        stale.unlink()
    messages: list[str] = []
    err_console = Console(stderr=True)
    killed = threading.Event()
    with (
        subprocess.Popen(
            job.command(exe), stderr=subprocess.PIPE, text=True, bufsize=1, errors="replace"
        ) as proc,
        TraceProgress(console=err_console, disable=not show_progress) as bar,
    ):
        assert proc.stderr is not None
        timer = None
        if job.timeout is not None:
            # Kill rtsim-sim when time is up; its stderr then closes and the loop below ends.
            timer = threading.Timer(job.timeout, lambda: (killed.set(), proc.kill()))
            timer.daemon = True
            timer.start()
        for line in proc.stderr:
            progress = parse_progress(line)
            if progress is not None:
                bar(progress[0], progress[1], "simulate")
                continue
            message = line.rstrip("\n")
            if not message:
                continue
            messages.append(message)
            if echo:
                err_console.print(message, markup=False, highlight=False)
        returncode = proc.wait()
        if timer is not None:
            timer.cancel()
    return SimResult(returncode, messages, read_stats(job.out_dir), timed_out=killed.is_set())


def describe_failure(returncode: int) -> str:
    if returncode < 0:
        return f"{SIM_EXE} was killed by signal {-returncode}"
    return f"{SIM_EXE} failed with exit code {returncode} (a crash, not a reported error)"


def simulate(job: SimJob, console: Console, show_progress: bool = True) -> int:
    """Runs one simulation and prints its summary; returns rtsim-sim's exit code."""
    result = run_sim(job, show_progress=show_progress)
    if result.timed_out:
        print(
            f"rtsim: error: {SIM_EXE} timed out after {job.timeout:g} s and was killed "
            f"(--timeout); run folder {job.out_dir} has no stats",
            file=sys.stderr,
        )
        return EXIT_TIMEOUT
    if result.returncode == EXIT_BAD_INPUT:
        return EXIT_BAD_INPUT  # rtsim-sim's message (naming the file or field) was echoed
    if result.returncode not in (EXIT_OK, EXIT_MISMATCH) or result.stats is None:
        what = describe_failure(result.returncode) if result.returncode else "no stats.json"
        print(f"rtsim: error: {what}; run folder {job.out_dir}", file=sys.stderr)
        return result.returncode if result.returncode > 0 else 1
    print_sim_summary(result.stats, console)
    console.print(f"run:      {job.out_dir}  (stats.json, config.resolved.json, provenance.json)")
    if job.timeline and (job.out_dir / "timeline.json").is_file():
        console.print(f"timeline: {job.out_dir / 'timeline.json'}  (open in ui.perfetto.dev)")
    if result.returncode == EXIT_MISMATCH:
        print_mismatches(result.stats, Console(stderr=True))
    return result.returncode


def positive_seconds(text: str) -> float:
    """An argparse type: a finite number of seconds > 0."""
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not (value > 0 and math.isfinite(value)):
        raise argparse.ArgumentTypeError(f"expected a number of seconds > 0, got '{text}'")
    return value


def cmd_simulate(args: argparse.Namespace, console: Console) -> int:
    job = SimJob(
        trace=Path(args.trace),
        out_dir=Path(args.output),
        config=Path(args.config) if args.config else None,
        sets=list(args.set or []),
        timeline=args.timeline,
        timeout=args.timeout,
    )
    return simulate(job, console, show_progress=not args.no_progress)


def cmd_config(args: argparse.Namespace, console: Console) -> int:
    flag = "--dump-schema" if args.schema else "--dump-defaults"
    result = subprocess.run([str(find_sim()), flag], capture_output=True, text=True, check=False)
    if result.returncode != 0:
        sys.stderr.write(result.stderr)
        return result.returncode if result.returncode > 0 else 1
    sys.stdout.write(result.stdout)
    return 0


def add_parsers(sub: argparse._SubParsersAction) -> None:  # type: ignore[type-arg]
    """Registers `simulate` and `config` on the `rtsim` subcommand parser."""
    p = sub.add_parser(
        "simulate",
        help="replay a trace on the SystemC accelerator model (rtsim-sim) and summarise the run",
        description="Replays TRACE on the accelerator model and writes RUN/stats.json, "
        "RUN/config.resolved.json and RUN/provenance.json. Exit codes: 0 ok, 2 bad input, "
        "3 simulated hits or work differ from the reference, 4 timed out (--timeout).",
    )
    p.add_argument("trace", metavar="TRACE", help="trace folder (from rtsim trace) or .rtt file")
    p.add_argument("--config", metavar="CFG.json", default=None, help="config JSON over defaults")
    p.add_argument(
        "--set",
        action="append",
        metavar="KEY=VALUE",
        default=[],
        help="override one config key, e.g. l1.size_kib=32 (repeatable; see rtsim config --schema)",
    )
    p.add_argument("-o", "--output", required=True, metavar="RUN", help="run folder")
    p.add_argument(
        "--timeline", action="store_true", help="also write RUN/timeline.json (Perfetto)"
    )
    p.add_argument(
        "--timeout",
        type=positive_seconds,
        default=None,
        metavar="SECONDS",
        help="kill rtsim-sim after this many seconds and exit with status 4 (default: no limit)",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_simulate)

    p = sub.add_parser("config", help="print the simulator's default config or its schema")
    group = p.add_mutually_exclusive_group(required=True)
    group.add_argument("--defaults", action="store_true", help="the default config as JSON")
    group.add_argument(
        "--schema", action="store_true", help="every field: default, unit, range, doc (JSON)"
    )
    p.set_defaults(func=cmd_config)
