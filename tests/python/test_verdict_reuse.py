"""The verdict's analysis is stepped once per trace and key, then reused (docs/verdict.md, "What
the verdict costs"): the first default run stores its sample analyses beside the trace, later
runs load it and weigh the same knobs to the same figures; with the cache off nothing is stored.

Each simulation is one `rtsim-sim` process on a private copy of the small cornell trace
(fixtures in test_model), so no other test's runs find its stored analysis.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path
from typing import Any

from test_model import cornell_small, trace_of  # noqa: F401  (fixtures)


def run(exe: Path, trace: Path, out: Path, env: dict[str, str] | None = None) -> dict[str, Any]:
    result = subprocess.run(
        [str(exe), str(trace), "-o", str(out)],
        capture_output=True, text=True, timeout=300, check=False, env=env,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    return json.loads((out / "stats.json").read_text())["verdict"]


def without_host(v: dict[str, Any], run: Path) -> dict[str, Any]:
    """The verdict less its wall time and reuse flag, and with its run folder (in the measure
    commands) named RUN."""
    v = json.loads(json.dumps(v).replace(str(run), "RUN"))
    del v["estimate"]["wall_seconds"], v["estimate"]["reused"]
    return v


def test_second_run_loads_the_stored_analysis(
    cornell_small: Path, sim_exe: Path, tmp_path: Path  # noqa: F811
) -> None:  # fmt: skip
    trace = tmp_path / "trace"
    shutil.copytree(cornell_small, trace, ignore=shutil.ignore_patterns("analytic"))
    env = {k: v for k, v in os.environ.items() if k != "RTSIM_ANALYTIC_CACHE"}
    first = run(sim_exe, trace, tmp_path / "one", env)
    assert first["estimate"]["reused"] is False
    stored = sorted((trace / "analytic").glob("*.json"))
    # The run's design and each design the verdict estimates on this trace (treelets flipped,
    # the other execution model), every one the verdict's sample.
    on_this_trace = [k for k in first["structural"] if k.get("speedup") and not k["trace"]]
    assert len(stored) == 1 + len(on_this_trace) >= 3
    assert all("verdict_sample" in json.loads(p.read_text())["key"] for p in stored)
    second = run(sim_exe, trace, tmp_path / "two", env)
    assert second["estimate"]["reused"] is True
    assert sorted((trace / "analytic").glob("*.json")) == stored  # nothing stepped again
    assert without_host(second, tmp_path / "two") == without_host(first, tmp_path / "one")


def test_cache_off_stores_nothing(cornell_small: Path, sim_exe: Path, tmp_path: Path) -> None:  # noqa: F811
    trace = tmp_path / "trace"
    shutil.copytree(cornell_small, trace, ignore=shutil.ignore_patterns("analytic"))
    env = {**os.environ, "RTSIM_ANALYTIC_CACHE": "off"}
    for name in ("one", "two"):
        assert run(sim_exe, trace, tmp_path / name, env)["estimate"]["reused"] is False
    assert not (trace / "analytic").exists()
