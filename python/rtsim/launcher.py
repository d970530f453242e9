"""Starts rtsim-sim: the one place a simulation process is launched, for `rtsim simulate`,
`rtsim.simulate()`, sweeps and `rtsim accuracy` (docs/architecture.md, rule 4: one simulation
per process, because SystemC elaborates once per process).

rtsim-sim reads a trace and a config, writes RUN/stats.json, RUN/config.resolved.json and
RUN/provenance.json, and exits 0 (ok), 2 (bad input: its message names the file or field) or 3
(simulated hits or work differ from the reference). Standard library only: importing this must
stay cheap (`rtsim simulate` pays for it on every run).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import sysconfig
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

SIM_EXE = "rtsim-sim"
EXIT_OK, EXIT_BAD_INPUT, EXIT_MISMATCH = 0, 2, 3
#: What rtsim-sim writes into the run folder (removed before a run: never stale).
RUN_OUTPUTS = (
    "stats.json",
    "config.resolved.json",
    "provenance.json",
    "dram_trace.dramsim3.txt",  # --dram-trace: a later run without it must not leave them behind
    "dram_requests.csv",
    "dram_trace.json",
)


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
    """One rtsim-sim run: a trace, a config (file and key=value overrides) and the run folder."""

    trace: Path
    out_dir: Path
    config: Path | None = None  # config JSON over the defaults
    sets: list[str] = field(default_factory=list)  # key.path=value, applied after config
    timeline: bool = False  # also write RUN/timeline.json
    dram_trace: bool = False  # also write RUN/dram_trace.* (the requests that reached DRAM)
    progress: bool = False  # JSON progress lines on stderr
    verdict: bool = True  # False: --no-verdict (no bottleneck estimates after the run)
    check_verdict: bool = False  # --check-verdict: re-run the verdict's top knobs (RUN/check/N)

    def command(self, exe: Path) -> list[str]:
        """The command line; sweeps record it in RUN/command.txt (keep the order stable)."""
        cmd = [str(exe), str(self.trace)]
        if self.config is not None:
            cmd += ["--config", str(self.config)]
        cmd += ["-o", str(self.out_dir)]
        for assignment in self.sets:
            cmd += ["--set", assignment]
        if self.timeline:
            cmd.append("--timeline")
        if self.dram_trace:
            cmd.append("--dram-trace")
        if self.progress:
            cmd.append("--progress")
        if not self.verdict:
            cmd.append("--no-verdict")
        elif self.check_verdict:
            cmd.append("--check-verdict")
        return cmd


@dataclass
class SimResult:
    """What one rtsim-sim process did."""

    command: list[str]
    returncode: int  # negative: killed by that signal (a timeout kills)
    stderr: str  # everything rtsim-sim wrote on stderr except progress lines
    stats: dict[str, Any] | None  # RUN/stats.json as this run wrote it, else None
    wall_seconds: float  # the whole process, start to exit
    timed_out: bool = False
    cpu_seconds: float = 0.0  # user + system CPU time of the process

    @property
    def messages(self) -> list[str]:
        return [line for line in self.stderr.splitlines() if line.strip()]

    def describe_failure(self) -> str:
        """Why there are no stats: a timeout, a signal or an unexpected exit code."""
        if self.timed_out:
            return f"{SIM_EXE} timed out"
        if self.returncode < 0:
            return f"{SIM_EXE} was killed by signal {-self.returncode}"
        if self.returncode in (EXIT_OK, EXIT_MISMATCH):
            return f"{SIM_EXE} exited with {self.returncode} but wrote no readable stats.json"
        return f"{SIM_EXE} failed with exit code {self.returncode}"


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


def read_json(path: Path) -> dict[str, Any] | None:
    """A JSON object from a file, or None if it is missing, unreadable or not an object."""
    try:
        data = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError):
        return None
    return data if isinstance(data, dict) else None


def run_sim(
    job: SimJob,
    *,
    exe: Path | None = None,
    timeout: float | None = None,
    on_progress: Callable[[int, int], None] | None = None,
    on_message: Callable[[str], None] | None = None,
    stdout: int | None = subprocess.DEVNULL,
) -> SimResult:
    """Runs one rtsim-sim process to completion (or until `timeout` seconds, then kills it).

    Progress lines (with job.progress) go to on_progress(done, total); every other non-empty
    stderr line to on_message as it arrives. Raises OSError if the process cannot start
    (SimNotFoundError if there is no rtsim-sim); every outcome of a started process, crashes
    and timeouts included, is returned."""
    from rtsim.args import timeout_arg

    timeout = timeout_arg(timeout)
    exe = exe or find_sim()
    if job.out_dir.exists() and not job.out_dir.is_dir():
        raise NotADirectoryError(f"{job.out_dir}: the run folder is a file")
    for stale in RUN_OUTPUTS:  # a stale stats.json must never pass for this run's
        (job.out_dir / stale).unlink(missing_ok=True)
    command = job.command(exe)
    kept: list[str] = []
    expired = threading.Event()
    t0 = time.perf_counter()
    with subprocess.Popen(
        command, stdout=stdout, stderr=subprocess.PIPE, text=True, bufsize=1, errors="replace"
    ) as proc:
        timer = None
        if timeout is not None:
            timer = threading.Timer(timeout, lambda: (expired.set(), proc.kill()))
            timer.daemon = True
            timer.start()
        try:
            assert proc.stderr is not None
            for line in proc.stderr:
                progress = parse_progress(line) if job.progress else None
                if progress is not None:
                    if on_progress is not None:
                        on_progress(*progress)
                    continue
                kept.append(line)
                if on_message is not None and line.strip():
                    on_message(line.rstrip("\n"))
            # wait4: the exit status and this child's own CPU time (rusage), with no other
            # concurrent child's mixed in.
            _, status, usage = os.wait4(proc.pid, 0)
            returncode = proc.returncode = os.waitstatus_to_exitcode(status)
        except BaseException:
            proc.kill()  # e.g. KeyboardInterrupt in a notebook: do not wait for the run to end
            raise
        finally:
            if timer is not None:
                timer.cancel()
    wall = time.perf_counter() - t0
    timed_out = expired.is_set() and returncode < 0
    stats = None if timed_out else read_json(job.out_dir / "stats.json")
    cpu = usage.ru_utime + usage.ru_stime
    return SimResult(command, returncode, "".join(kept), stats, wall, timed_out, cpu)
