"""What a Dask worker runs: make one trace (`rtsim trace` as a subprocess) or one simulation
(`rtsim-sim` through rtsim/launcher.py; docs/architecture.md, rule 4). Both never raise: every
failure, crash or timeout comes back as a dict with status "failed" and the tail of the process's
stderr, so the client records it and the sweep goes on. Paths are absolute: with --scheduler the
workers must see the sweep folder at the same path (a shared file system).
"""

from __future__ import annotations

import json
import os
import shutil
import socket
import subprocess
import sys
import time
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

TRACE_DONE = "trace.complete"  # written last: a trace folder without it is redone
ERROR_TAIL_LINES = 15


def utc_now() -> str:
    return datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%S.%fZ")


def stderr_tail(text: str, lines: int = ERROR_TAIL_LINES) -> str:
    """The last lines of a process's stderr, without progress lines."""
    kept = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("{")]
    return "\n".join(kept[-lines:])


@dataclass
class TraceTask:
    trace_dir: str
    scene: str
    rays: list[str]  # empty: every kind the scene calls for
    width: int
    height: int
    bounces: int
    seed: int
    hairball_triangles: int
    accel: str = "bvh2"  # the structure (rtsim trace --accel)
    builder: str = ""  # its builder; empty: the structure's default
    build_settings: dict[str, Any] = field(default_factory=dict)  # rtsim trace --build-set
    frames: int = 1  # rtsim trace --frames N (an animated trace)
    frame_policy: str = "rebuild"  # rtsim trace --frame-policy
    rebuild_threshold: float = 1.25  # rtsim trace --rebuild-threshold (adaptive)
    flatten: bool = False  # rtsim trace --flatten (instanced scenes: one world-space structure)
    lights: str = ""  # rtsim trace --lights (a scene without lights given some); "": none
    reflections: str = "mirror"  # rtsim trace --reflections
    roulette_after: int = 0  # rtsim trace --roulette-after (0: off)
    alternatives: bool = False  # rtsim trace --alternatives (other structures beside it)

    def command(self, out: str) -> list[str]:
        workload = ["--workload", ",".join(self.rays)] if self.rays else []
        return [
            sys.executable,
            "-m",
            "rtsim",
            "trace",
            self.scene,
            "-o",
            out,
            *workload,
            "--resolution",
            f"{self.width}x{self.height}",
            "--bounces",
            str(self.bounces),
            "--seed",
            str(self.seed),
            "--hairball-triangles",
            str(self.hairball_triangles),
            "--accel",
            self.accel,
            *(["--builder", self.builder] if self.builder else []),
            *[
                a
                for k, v in self.build_settings.items()
                for a in ("--build-set", f"{k}={_text(v)}")
            ],
            *(["--frames", str(self.frames)] if self.frames != 1 else []),
            *(["--frame-policy", self.frame_policy] if self.frame_policy != "rebuild" else []),
            *(
                ["--rebuild-threshold", str(self.rebuild_threshold)]
                if self.rebuild_threshold != 1.25
                else []
            ),
            *(["--flatten"] if self.flatten else []),
            *(["--lights", self.lights] if self.lights else []),
            *(["--reflections", self.reflections] if self.reflections != "mirror" else []),
            *(["--roulette-after", str(self.roulette_after)] if self.roulette_after else []),
            *(["--alternatives"] if self.alternatives else []),
        ]


def _text(value: Any) -> str:
    """A setting's value as --build-set takes it (true/false, numbers as JSON writes them)."""
    return json.dumps(value)


def trace_ready(trace_dir: Path) -> bool:
    return (trace_dir / TRACE_DONE).is_file() and (trace_dir / "trace.rtt").is_file()


def make_trace(task: TraceTask, timeout: float | None = None) -> dict[str, Any]:
    """Traces into a temporary folder and renames it into place, so a killed sweep never
    leaves a half-written trace that passes for a whole one. Reuses a finished trace."""
    final = Path(task.trace_dir)
    if trace_ready(final):
        return {"ok": True, "reused": True, "trace_dir": str(final)}
    tmp = final.with_name(f"{final.name}.tmp-{socket.gethostname()}-{os.getpid()}")
    shutil.rmtree(tmp, ignore_errors=True)
    t0 = time.monotonic()
    try:
        proc = subprocess.run(
            task.command(str(tmp)),
            capture_output=True,
            text=True,
            timeout=timeout,
            check=False,
            errors="replace",
        )
    except subprocess.TimeoutExpired:
        shutil.rmtree(tmp, ignore_errors=True)
        return {"ok": False, "error": f"tracing timed out after {timeout:g} s"}
    except OSError as err:
        return {"ok": False, "error": f"cannot run rtsim trace: {err}"}
    if proc.returncode != 0:
        shutil.rmtree(tmp, ignore_errors=True)
        return {
            "ok": False,
            "error": f"rtsim trace exited with {proc.returncode}: " + stderr_tail(proc.stderr),
        }
    (tmp / TRACE_DONE).write_text(
        json.dumps({"command": task.command(str(final)), "seconds": time.monotonic() - t0})
    )
    if final.exists():
        shutil.rmtree(final)
    tmp.rename(final)
    return {"ok": True, "reused": False, "trace_dir": str(final), "seconds": time.monotonic() - t0}


@dataclass
class SimTask:
    run_id: str
    trace_dir: str
    run_dir: str
    config: dict[str, Any]
    timeout: float | None = None


def _failed(error: str, **extra: Any) -> dict[str, Any]:
    return {"status": "failed", "error": error, "stats": None, "provenance": None, **extra}


def run_sim(task: SimTask, trace: dict[str, Any] | None = None) -> dict[str, Any]:
    """Runs one rtsim-sim process; returns its outcome (never raises).

    The run folder holds config.json (input), command.txt, stderr.log and what rtsim-sim writes:
    config.resolved.json, stats.json, provenance.json (version, git hash, command line)."""
    started, t0 = utc_now(), time.monotonic()
    base = {"started_utc": started, "worker": f"{socket.gethostname()}:{os.getpid()}"}

    def done(outcome: dict[str, Any]) -> dict[str, Any]:
        return {**base, **outcome, "finished_utc": utc_now(), "wall_seconds": time.monotonic() - t0}

    if trace is not None and not trace.get("ok"):
        return done(_failed(f"no trace: {trace.get('error')}", exit_code=None))
    try:
        from rtsim.launcher import SimJob, find_sim
        from rtsim.launcher import run_sim as launch

        exe = find_sim()
    except (ImportError, OSError) as err:
        return done(_failed(str(err), exit_code=None))
    run = Path(task.run_dir)
    run.mkdir(parents=True, exist_ok=True)
    (run / "config.json").write_text(json.dumps(task.config, indent=2, sort_keys=True) + "\n")
    job = SimJob(trace=Path(task.trace_dir), out_dir=run, config=run / "config.json")
    (run / "command.txt").write_text(" ".join(job.command(exe)) + "\n")
    try:
        result = launch(job, exe=exe, timeout=task.timeout)
    except OSError as err:
        return done(_failed(f"cannot run {exe}: {err}", exit_code=None))
    if result.timed_out:
        tail = stderr_tail(result.stderr)
        msg = f"timed out after {task.timeout:g} s" + (f": {tail}" if tail else "")
        return done(_failed(msg, exit_code=None))
    (run / "stderr.log").write_text(result.stderr)
    return done(_outcome(result.returncode, result.stderr, result.stats))


def _outcome(code: int, stderr: str, stats: dict[str, Any] | None) -> dict[str, Any]:
    if code not in (0, 3):
        what = f"killed by signal {-code}" if code < 0 else f"exit code {code}"
        return _failed(f"rtsim-sim {what}: {stderr_tail(stderr) or '(no message)'}", exit_code=code)
    if stats is None:
        return _failed(f"rtsim-sim exit code {code} but no readable stats.json", exit_code=code)
    status = "ok" if code == 0 else "mismatch"
    error = (
        None if code == 0 else "simulated hits differ from the reference: " + stderr_tail(stderr)
    )
    return {
        "status": status,
        "exit_code": code,
        "error": error,
        "stats": stats,
        "provenance": stats.get("provenance"),
    }
