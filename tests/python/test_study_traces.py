"""What studies read from traces (rtsim/study/traces.py): per-ray work of one ray kind, hit
differences between two structures' traces of the same rays, and a trace made again under
/usr/bin/time from the command the sweep recorded."""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

import rtsim
from rtsim.study.traces import hits_differ, manifest, retrace, work_stats
from rtsim.sweep.tasks import TRACE_DONE


def test_work_stats_of_one_ray_kind(small_cornell_rays: Path) -> None:
    t = rtsim.open_trace(small_cornell_rays)
    kinds = np.asarray(t.rays["kind"])
    shadow = kinds == rtsim.trace_file.RAY_KINDS.index("shadow")
    every, only = work_stats(small_cornell_rays), work_stats(small_cornell_rays, "shadow")
    assert every["rays"] == len(kinds) and only["rays"] == int(shadow.sum()) > 0
    steps = np.asarray(t.work)["steps"][shadow].astype(float)
    assert only["steps"]["sum"] == steps.sum() < every["steps"]["sum"]
    assert only["steps"]["p99"] == pytest.approx(np.percentile(steps, 99))
    assert 0.0 < only["hit_rate"] <= 1.0


def test_hits_differ_between_structures_of_the_same_rays(tmp_path: Path) -> None:
    for accel in ("bvh2", "bvh8"):
        rtsim.trace_scene("cornell", tmp_path / accel, "primary", 16, 12, accel=accel)
    assert hits_differ(tmp_path / "bvh8", tmp_path / "bvh2") == 0
    assert manifest(tmp_path / "bvh8")["accel"]["kind"] == "bvh8"


@pytest.mark.skipif(shutil.which("/usr/bin/time") is None, reason="needs /usr/bin/time")
def test_retrace_reruns_the_recorded_command(tmp_path: Path) -> None:
    folder = tmp_path / "trace"
    cmd = [sys.executable, "-m", "rtsim", "trace", "cornell", "-o", str(folder)]
    cmd += ["--workload", "primary", "--resolution", "8x6"]
    rtsim.trace_scene("cornell", folder, "primary", 8, 6)
    (folder / TRACE_DONE).write_text(json.dumps({"command": cmd}))
    timing = retrace(folder, repeat=2)
    assert timing["build_ms"] >= 0 and timing["peak_mib"] > 1
    assert (folder / "trace.rtt").is_file()  # made again elsewhere, the original kept
