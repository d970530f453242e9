"""The TLAS/BLAS split of a two-level walk (docs/stats.md, `two_level`): the TLAS's node steps and
box tests are counted apart by the stepper (model-only work fields, never in a trace), so a run
of an instanced scene reports both levels, and the two add up to the trace's totals."""

from __future__ import annotations

from pathlib import Path

import pytest

import rtsim
from conftest import rtsim_trace, sim_stats


@pytest.mark.parametrize("level", ["functional", "approx"])
def test_two_level_runs_split_tlas_and_blas_work(
    scenes_dir: Path, sim_exe: Path, tmp_path: Path, level: str
) -> None:
    trace = tmp_path / "trace"
    rtsim_trace(
        str(scenes_dir / "SimpleInstancing" / "SimpleInstancing.gltf"),
        "-o", str(trace), "--resolution", "32x24",
    )  # fmt: skip
    stats = sim_stats(sim_exe, trace, tmp_path / "run", f"fidelity={level}")
    assert stats["summary"]["hit_mismatches"] == stats["summary"]["work_mismatches"] == 0
    split = stats["two_level"]
    work = rtsim.open_trace(trace).work
    assert split["tlas_steps"] + split["blas_steps"] == int(work["steps"].sum())
    assert split["tlas_box_tests"] + split["blas_box_tests"] == int(work["box_tests"].sum())
    assert split["tlas_box_tests"] == 2 * split["tlas_steps"] > 0
    assert split["blas_steps"] > 0 and split["transforms"] == int(work["transforms"].sum()) > 0
    assert 0 < split["tlas_step_fraction"] < 1


def test_single_level_runs_have_no_split(
    cornell_trace: Path, sim_exe: Path, tmp_path: Path
) -> None:
    assert "two_level" not in sim_stats(sim_exe, cornell_trace, tmp_path / "run")
