"""`rtsim simulate` and `rtsim config` end to end: rtsim-sim runs, the run folder, exit codes."""

from __future__ import annotations

import json
import os
import re
import subprocess
from pathlib import Path
from typing import Any

import pytest

import rtsim
from conftest import REPO, rtsim_command, rtsim_trace, run_rtsim
from rtsim.launcher import parse_progress


@pytest.fixture(scope="module")
def tiny_trace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A 48x32 cornell trace with every ray kind (shadow rays take the any-hit path)."""
    out = tmp_path_factory.mktemp("sim") / "trace"
    rtsim_trace(
        "cornell",
        "-o",
        str(out),
        "--workload",
        "primary,shadow,reflection,diffuse",
        "--resolution",
        "48x32",
    )
    return out


@pytest.fixture(scope="module")
def tiny_run(tiny_trace: Path) -> tuple[Path, str]:
    run = tiny_trace.parent / "run"
    result = run_rtsim("simulate", str(tiny_trace), "-o", str(run), "--set", "traversal.units=2")
    assert result.returncode == 0, result.stdout + result.stderr
    return run, result.stdout


def test_simulate_writes_run_folder(tiny_trace: Path, tiny_run: tuple[Path, str]) -> None:
    run, stdout = tiny_run
    for name in ("stats.json", "config.resolved.json", "provenance.json"):
        assert (run / name).is_file(), name
    stats = json.loads((run / "stats.json").read_text())
    rays = len(rtsim.open_trace(tiny_trace).rays)
    assert stats["summary"]["rays"] == rays > 0
    assert stats["validation"]["rays_checked"] == rays
    assert stats["summary"]["hit_mismatches"] == stats["summary"]["work_mismatches"] == 0
    assert stats["summary"]["cycles"] > 0
    # --set reached the model: two traversal units, and the resolved config says so.
    assert sorted(stats["model"]["units"]) == ["tu0", "tu1"]
    resolved = json.loads((run / "config.resolved.json").read_text())
    assert resolved["traversal"]["units"] == 2
    provenance = json.loads((run / "provenance.json").read_text())
    assert "traversal.units=2" in provenance["command_line"]
    # The summary table is printed.
    assert "Mrays/s" in stdout and "L1 hit rate" in stdout and "p99" in stdout


def test_bad_config_exits_2_naming_the_key(tiny_trace: Path, tmp_path: Path) -> None:
    result = run_rtsim(
        "simulate", str(tiny_trace), "-o", str(tmp_path / "run"), "--set", "l1.size_kib=3"
    )
    assert result.returncode == 2
    assert "l1.size_kib" in result.stderr
    assert not (tmp_path / "run" / "stats.json").exists()


def test_memory_check_counts_the_image_bytes_not_its_addresses(
    tiny_trace: Path, tmp_path: Path
) -> None:
    """The structure's regions sit at addresses from 4 GiB up (accel_image.h): a host with a few
    GiB must still run a tiny trace (the check once took the image's end address for its size
    and asked for 24 GiB)."""
    env = {**os.environ, "RTSIM_SIM_MEMORY_LIMIT_MIB": "1024"}
    cmd = [*rtsim_command(), "simulate", str(tiny_trace), "-o", str(tmp_path / "run")]
    result = subprocess.run(cmd, capture_output=True, text=True, env=env, check=False)
    assert result.returncode == 0, result.stderr
    env["RTSIM_SIM_MEMORY_LIMIT_MIB"] = "1"  # below the process's own base: refused, named
    result = subprocess.run(cmd, capture_output=True, text=True, env=env, check=False)
    assert result.returncode == 2 and "RTSIM_SIM_MEMORY_LIMIT_MIB" in result.stderr


def test_unknown_key_exits_2(tiny_trace: Path, tmp_path: Path) -> None:
    result = run_rtsim(
        "simulate", str(tiny_trace), "-o", str(tmp_path / "run"), "--set", "l1.sise_kib=32"
    )
    assert result.returncode == 2
    assert "l1.sise_kib" in result.stderr


def test_missing_trace_exits_2(tmp_path: Path) -> None:
    result = run_rtsim("simulate", str(tmp_path / "nothing"), "-o", str(tmp_path / "run"))
    assert result.returncode == 2
    assert "nothing" in result.stderr


def test_timeline(tiny_trace: Path, tmp_path: Path) -> None:
    run = tmp_path / "run"
    result = run_rtsim("simulate", str(tiny_trace), "-o", str(run), "--timeline", "--no-progress")
    assert result.returncode == 0, result.stderr
    timeline = json.loads((run / "timeline.json").read_text())
    spans = [e for e in timeline["traceEvents"] if e.get("ph") == "X"]
    assert spans and all(e["dur"] >= 0 for e in spans)


def test_config_schema_and_defaults() -> None:
    result = run_rtsim("config", "--schema")
    assert result.returncode == 0, result.stderr
    schema = json.loads(result.stdout)
    sections = {k for k, v in schema.items() if v.get("type") == "section"}
    assert {"traversal", "box", "triangle", "l1", "l2", "dram"} <= sections
    assert schema["l1"]["fields"]["size_kib"]["unit"] == "KiB"
    result = run_rtsim("config", "--defaults")
    assert result.returncode == 0, result.stderr
    defaults = json.loads(result.stdout)
    assert defaults["l1"]["size_kib"] == schema["l1"]["fields"]["size_kib"]["default"]


def test_parse_progress() -> None:
    assert parse_progress('{"progress": 4096, "total": 10000}\n') == (4096, 10000)
    assert parse_progress("rtsim-sim: error: config: 'x'") is None
    assert parse_progress('{"other": 1}') is None
    assert parse_progress("{not json") is None


# Instance names and data or ray kinds that docs/stats.md writes as placeholders.
PLACEHOLDER = re.compile(
    r"^(tu\d+|l1_\d+|(box|triangle|anyhit|transform|cell)_(\d+|pool)|node|triangle|ray|hit|stack"
    r"|primary|shadow|reflection|diffuse|refraction)$"
)


def stats_keys(node: Any, path: tuple[str, ...] = ()) -> list[tuple[str, ...]]:
    """Every dict key path of stats.json (lists are not entered)."""
    out = []
    if isinstance(node, dict):
        for key, value in node.items():
            out.append((*path, key))
            out += stats_keys(value, (*path, key))
    return out


def test_every_stats_key_is_documented(tiny_trace: Path, tiny_run: tuple[Path, str]) -> None:
    """docs/stats.md names every key of a real stats.json (default and ideal-memory runs)."""
    doc = (REPO / "docs" / "stats.md").read_text()
    documented = set()
    for token in re.findall(r"`([A-Za-z0-9_.<> ]+)`", doc):
        documented.update(token.split("."))
    ideal = tiny_trace.parent / "run_ideal"
    result = run_rtsim(
        "simulate", str(tiny_trace), "-o", str(ideal), "--set", "ideal_memory=true", "--no-progress"
    )
    assert result.returncode == 0, result.stderr
    missing = set()
    for run in (tiny_run[0], ideal):
        stats = json.loads((run / "stats.json").read_text())
        for path in stats_keys(stats):
            if not PLACEHOLDER.match(path[-1]) and path[-1] not in documented:
                missing.add(".".join(path))
    assert not missing, f"keys of stats.json not in docs/stats.md: {sorted(missing)}"


FAKE_SIM = """#!/bin/sh
# A stand-in rtsim-sim that reports mismatches: TRACE -o RUN --progress
mkdir -p "$3"
echo '{"progress": 1, "total": 2}' >&2
echo 'fake-sim: a message' >&2
cat > "$3/stats.json" <<'JSON'
{"fidelity": "functional",
 "summary": {"rays": 2, "cycles": null, "hit_mismatches": 1, "work_mismatches": 0},
 "validation": {"rays_checked": 2, "hit_mismatches": 1, "work_mismatches": 0,
   "first_mismatches": [{"ray": 1, "difference": "hit: model prim 3, reference prim 4"}]}}
JSON
exit 3
"""


def test_mismatch_exit_3_is_loud(tmp_path: Path) -> None:
    fake = tmp_path / "fake-sim"
    fake.write_text(FAKE_SIM)
    fake.chmod(0o755)
    env = {**os.environ, "RTSIM_SIM": str(fake)}
    result = subprocess.run(
        [*rtsim_command(), "simulate", "trace", "-o", str(tmp_path / "run")],
        capture_output=True,
        text=True,
        env=env,
        check=False,
    )
    assert result.returncode == 3
    assert "MISMATCH" in result.stderr and "ray 1" in result.stderr
    assert "fake-sim: a message" in result.stderr  # other stderr lines pass through
    assert '"progress"' not in result.stderr  # progress lines drive the bar instead
