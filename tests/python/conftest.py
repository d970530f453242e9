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


def rtsim_trace(*args: str) -> None:
    """`rtsim trace ARGS` through the command line, asserted to succeed (stderr shown if not)."""
    result = run_rtsim("trace", *args)
    assert result.returncode == 0, result.stderr


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


def trace_per_structure(
    root: Path,
    scene: str,
    resolution: str,
    workload: str,
    structures: dict[str, list[str]],
    *extra: str,
) -> dict[str, Path]:
    """`rtsim trace SCENE` once per structure (name: its command-line arguments) under root."""
    out = {}
    for name, args in structures.items():
        folder = root / name
        rtsim_trace(
            scene, "-o", str(folder), "--resolution", resolution, "--workload", workload,
            *extra, *args,
        )  # fmt: skip
        out[name] = folder
    return out


@pytest.fixture(scope="session")
def small_hairball_traces(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """A 2,000-triangle hairball at 32x24 (primary and diffuse), once per structure (bvh2,
    cwbvh8, kdtree): the traces the short-stack and reduced-precision box tests replay."""
    structures = {accel: ["--accel", accel] for accel in ("bvh2", "cwbvh8", "kdtree")}
    return trace_per_structure(
        tmp_path_factory.mktemp("small_hairball_traces"), "hairball", "32x24", "primary,diffuse",
        structures, "--hairball-triangles", "2000",
    )  # fmt: skip


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
    rtsim_trace(
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
    return out


@pytest.fixture(scope="session")
def small_cornell_rays(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Cornell primary, shadow and diffuse rays at 32x24 (the execution models' tests)."""
    out = tmp_path_factory.mktemp("small_cornell_rays") / "cornell"
    rtsim.trace_scene("cornell", out, workload="primary,shadow,diffuse", width=32, height=24)
    return out


@pytest.fixture(scope="session")
def same_ray_trace(tmp_path_factory: pytest.TempPathFactory, small_cornell_rays: Path) -> Path:
    """128 copies of one primary ray that hits the scene: every lane of a warp or packet alike."""
    import numpy as np

    t = rtsim.open_trace(small_cornell_rays)
    rays, hits = t.rays, t.hits
    i = int(np.flatnonzero(hits["prim"] >= 0)[len(hits) // 4])
    n = 128
    out = tmp_path_factory.mktemp("same_ray") / "t"
    rtsim.write_trace(
        "cornell",
        np.repeat(rays["origin"][i : i + 1], n, axis=0),
        np.repeat(rays["direction"][i : i + 1], n, axis=0),
        float(rays["tmin"][i]),
        float(rays["tmax"][i]),
        out=out,
    )
    return out
