"""rtsim/launcher.py is the one way rtsim-sim is started: by `rtsim simulate`, rtsim.simulate(),
sweeps and `rtsim accuracy`; sweeps record the same command line as before it existed."""

from __future__ import annotations

import subprocess
import time
from pathlib import Path
from typing import Any

import pytest

import rtsim
from rtsim import accuracy, launcher, sim_cli
from rtsim.sweep import tasks

SLOW_SIM = """#!/bin/sh
echo '{"progress": 1, "total": 4}' >&2
echo 'slow-sim: started' >&2
exec sleep 30
"""


@pytest.fixture(scope="module")
def trace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("launcher") / "trace"
    rtsim.trace_scene("cornell", out, workload="primary", width=16, height=12)
    return out


def test_sweep_command_line_is_unchanged(tmp_path: Path) -> None:
    """What a sweep writes to RUN/command.txt (and rtsim-sim to provenance.json)."""
    exe, trace, run = Path("/x/rtsim-sim"), tmp_path / "t", tmp_path / "run"
    job = launcher.SimJob(trace=trace, out_dir=run, config=run / "config.json")
    assert job.command(exe) == [str(exe), str(trace), "--config", str(run / "config.json"),
                                "-o", str(run)]  # fmt: skip


def test_every_caller_goes_through_the_launcher(
    trace: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    started: list[list[str]] = []
    real_popen = subprocess.Popen

    def recording_popen(cmd: list[str], *args: Any, **kwargs: Any) -> Any:
        started.append(list(cmd))
        return real_popen(cmd, *args, **kwargs)

    monkeypatch.setattr(launcher.subprocess, "Popen", recording_popen)
    exe = launcher.find_sim()

    rtsim.simulate(trace, fidelity="functional")
    assert len(started) == 1

    from rich.console import Console

    job = launcher.SimJob(trace=trace, out_dir=tmp_path / "cli", sets=["fidelity=functional"])
    with (tmp_path / "summary.txt").open("w") as summary:
        assert sim_cli.run_and_report(job, Console(file=summary)) == 0
    assert "rays" in (tmp_path / "summary.txt").read_text()
    assert len(started) == 2 and "--progress" in started[-1]  # drives the progress bar

    task = tasks.SimTask("id", str(trace), str(tmp_path / "sweep"), {"fidelity": "functional"})
    assert tasks.run_sim(task)["status"] == "ok"
    assert len(started) == 3
    recorded = (tmp_path / "sweep" / "command.txt").read_text().split()
    assert recorded == started[-1]  # command.txt is exactly what ran

    wall, code, stats, _ = accuracy.run_once(exe, trace, tmp_path / "acc", ["fidelity=functional"])
    assert code == 0 and stats is not None and wall > 0
    assert len(started) == 4
    assert all(cmd[0] == str(exe) and cmd[1] == str(trace) for cmd in started)


def test_timeout_kills_the_process(tmp_path: Path) -> None:
    fake = tmp_path / "slow-sim"
    fake.write_text(SLOW_SIM)
    fake.chmod(0o755)
    progress: list[tuple[int, int]] = []
    messages: list[str] = []
    t0 = time.monotonic()
    result = launcher.run_sim(
        launcher.SimJob(trace=tmp_path, out_dir=tmp_path / "run", progress=True),
        exe=fake,
        timeout=0.5,
        on_progress=lambda done, total: progress.append((done, total)),
        on_message=messages.append,
    )
    assert time.monotonic() - t0 < 10
    assert result.timed_out and result.returncode < 0 and result.stats is None
    assert progress == [(1, 4)] and messages == ["slow-sim: started"]
    assert result.stderr == "slow-sim: started\n"  # progress lines are not kept
    assert "timed out" in result.describe_failure()


def test_stale_outputs_are_removed_before_a_run(trace: Path, tmp_path: Path) -> None:
    run = tmp_path / "run"
    run.mkdir()
    for name in launcher.RUN_OUTPUTS:
        (run / name).write_text('{"stale": true}')
    result = launcher.run_sim(launcher.SimJob(trace=tmp_path / "missing", out_dir=run))
    assert result.returncode == launcher.EXIT_BAD_INPUT and "missing" in result.stderr
    assert result.stats is None
    assert not any((run / name).exists() for name in launcher.RUN_OUTPUTS)
