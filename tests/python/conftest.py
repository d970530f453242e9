"""Shared fixtures: the cornell scene, the shared scene folder, one small traced folder, and the
rtsim-sim the package runs (with a helper that runs it and returns the stats)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import rtsim
from rtsim.launcher import SimJob, SimNotFoundError, SimResult, find_sim, run_sim

REPO = Path(__file__).resolve().parents[2]
TRACE_WIDTH, TRACE_HEIGHT = 64, 48
TRACE_WORKLOAD = "primary,shadow,reflection,diffuse"


def rtsim_command() -> list[str]:
    """The installed console script next to this Python, else `python -m rtsim`."""
    script = Path(sys.executable).parent / "rtsim"
    if script.exists():
        return [str(script)]
    found = shutil.which("rtsim")
    return [found] if found else [sys.executable, "-m", "rtsim"]


def run_rtsim(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [*rtsim_command(), *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=600,
        check=False,
    )


def sim_or_fail() -> Path:
    """The rtsim-sim the package would run (rtsim.launcher.find_sim), or fail the test."""
    try:
        return find_sim()
    except SimNotFoundError as error:
        pytest.fail(str(error))


@pytest.fixture(scope="session")
def sim_exe() -> Path:
    return sim_or_fail()


def simulate(sim_exe: Path, trace: Path, out: Path, *sets: str) -> SimResult:
    """One `rtsim-sim TRACE -o OUT --set ...` through the one launcher (rtsim/launcher.py)."""
    return run_sim(SimJob(trace=trace, out_dir=out, sets=list(sets)), exe=sim_exe, timeout=300)


def sim_stats(sim_exe: Path, trace: Path, out: Path, *sets: str) -> dict:
    """Runs `rtsim-sim TRACE -o OUT --set ...`, asserts it succeeded and returns its stats.json."""
    result = simulate(sim_exe, trace, out, *sets)
    assert result.returncode == 0 and result.stats is not None, result.stderr
    return result.stats


def checked(sim_exe: Path, trace: Path, out: Path, *sets: str) -> dict:
    """sim_stats, asserting every ray was checked with zero hit and work mismatches."""
    stats = sim_stats(sim_exe, trace, out, *sets)
    s = stats["summary"]
    assert s["hit_mismatches"] == 0 and s["work_mismatches"] == 0, stats["validation"]
    assert s["rays"] == stats["validation"]["rays_checked"] > 0
    return stats


@pytest.fixture(scope="session")
def small_hairball_traces(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """A 2,000-triangle hairball at 32x24 (primary and diffuse), once per structure (bvh2,
    cwbvh8, kdtree): the traces the short-stack and reduced-precision box tests replay."""
    root = tmp_path_factory.mktemp("small_hairball_traces")
    out = {}
    for accel in ("bvh2", "cwbvh8", "kdtree"):
        folder = root / accel
        result = run_rtsim(
            "trace", "hairball", "-o", str(folder), "--resolution", "32x24",
            "--workload", "primary,diffuse", "--hairball-triangles", "2000", "--accel", accel,
        )  # fmt: skip
        assert result.returncode == 0, result.stderr
        out[accel] = folder
    return out


@pytest.fixture(scope="session")
def cornell() -> rtsim.Scene:
    return rtsim.load_scene("cornell")


@pytest.fixture(scope="session")
def scenes_dir() -> Path:
    env = os.environ.get("RTSIM_SCENES")
    path = Path(env) if env else REPO.parent / "shared" / "scenes"
    if not path.is_dir():
        pytest.skip(f"shared scenes not found (RTSIM_SCENES={env!r})")
    return path


@pytest.fixture(scope="session")
def cornell_trace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """`rtsim trace cornell` run once through the command line; returns the trace folder."""
    out = tmp_path_factory.mktemp("cornell") / "trace"
    result = run_rtsim(
        "trace",
        "cornell",
        "-o",
        str(out),
        "--workload",
        TRACE_WORKLOAD,
        "--resolution",
        f"{TRACE_WIDTH}x{TRACE_HEIGHT}",
        "--bounces",
        "2",
    )
    assert result.returncode == 0, result.stderr
    return out
