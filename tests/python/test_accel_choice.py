"""The structure is a choice everywhere: every registered kind (and the SBVH
builder) records kind, builder, width, node bytes, footprint and SAH cost in the manifest, and
`rtsim simulate` takes the structure from the trace, with no option naming it."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from conftest import rtsim_trace, run_rtsim
from rtsim import _core

KINDS = [k["name"] for k in _core.accel_kinds()]
ACCELS = [*KINDS, "bvh2:sbvh"]
MANIFEST_KEYS = ("kind", "builder", "width", "node_bytes", "footprint_bytes", "sah_cost")


@pytest.fixture(scope="module")
def trace_of(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str], Path]:
    root = tmp_path_factory.mktemp("choice")
    made: dict[str, Path] = {}

    def trace(accel: str) -> Path:
        if accel not in made:
            kind, _, builder = accel.partition(":")
            out = root / accel.replace(":", "-")
            args = ["cornell", "-o", str(out), "--accel", kind]
            args += ["--workload", "primary", "--resolution", "16x12"]
            args += ["--builder", builder] if builder else []
            rtsim_trace(*args)
            made[accel] = out
        return made[accel]

    return trace


def manifest_accel(trace: Path) -> dict[str, Any]:
    return dict(json.loads((trace / "manifest.json").read_text())["accel"])


@pytest.mark.parametrize("accel", ACCELS)
def test_manifest_records_the_structure(trace_of: Callable[[str], Path], accel: str) -> None:
    a = manifest_accel(trace_of(accel))
    assert all(key in a for key in MANIFEST_KEYS), sorted(a)
    kind, _, builder = accel.partition(":")
    assert a["kind"] == kind and a["builder"] == (builder or a["builder"]) and a["builder"]
    assert a["footprint_bytes"] == sum(r["bytes"] for r in a["regions"]) > 0
    assert isinstance(a["node_bytes"], int) and a["node_bytes"] > 0
    if kind == "grid":  # no branching width, no SAH cost: recorded as null, not left out
        assert a["width"] is None and a["sah_cost"] is None
    else:
        assert a["width"] in (2, 4, 6, 8) and a["sah_cost"] > 0


@pytest.mark.parametrize("accel", ["grid", "cwbvh8", "bvh2:sbvh"])
def test_simulate_takes_the_structure_from_the_trace(
    trace_of: Callable[[str], Path], tmp_path: Path, accel: str
) -> None:
    run = tmp_path / "run"
    result = run_rtsim("simulate", str(trace_of(accel)), "-o", str(run), "--no-progress")
    assert result.returncode == 0, result.stderr
    stats = json.loads((run / "stats.json").read_text())
    assert stats["summary"]["hit_mismatches"] == 0 and stats["summary"]["work_mismatches"] == 0
    blocks = {b["block"]: b for b in stats["instantiated"]}
    kind = accel.partition(":")[0]
    # only the grid issues cell steps (every structure box-tests: the grid its scene box once)
    assert blocks["cell"]["instantiated"] == (kind == "grid")
    assert blocks["box"]["instantiated"]
    assert f"the {kind} structure" in blocks["cell"]["why"]
