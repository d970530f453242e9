"""--dram-trace (the requests that reached DRAM, for DRAMsim3 and Ramulator 2) and the conversions
of scripts/dram_compare.py."""

from __future__ import annotations

import argparse
import importlib.util
import json
import sys
from pathlib import Path

import pytest

from test_model import Sim, cornell_small, sim, trace_of  # noqa: F401  (fixtures)

REPO = Path(__file__).resolve().parents[2]


def dram_compare():
    path = REPO / "scripts" / "dram_compare.py"
    spec = importlib.util.spec_from_file_location("dram_compare", path)
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    sys.modules["dram_compare"] = module  # its dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


def test_dram_trace_matches_the_runs_dram_counters(
    cornell_small: Path,  # noqa: F811
    sim: Sim,  # noqa: F811
    tmp_path: Path,
) -> None:
    trace = cornell_small
    run = tmp_path / "run"
    p = sim(trace, run, "dram.channels=1", extra=("--dram-trace", "--no-verdict"))
    assert p.returncode == 0, p.stderr
    stats = json.loads((run / "stats.json").read_text())
    dram = stats["model"]["dram"]
    summary = json.loads((run / "dram_trace.json").read_text())
    assert summary["reads"] == dram["reads"] and summary["writes"] == dram["writes"]
    assert summary["bytes"] == dram["read_bytes"] + dram["write_bytes"]
    assert summary["dram"]["channels"] == 1 and summary["dropped"] == 0
    # Loaded reads take at least the unloaded latency of a row hit (latency - tRCD).
    assert summary["mean_read_latency_cycles"] >= summary["dram"]["latency"] - 14
    lines = (run / "dram_trace.dramsim3.txt").read_text().splitlines()
    cycles = [int(line.split()[2]) for line in lines]
    assert cycles == sorted(cycles)  # DRAMsim3 reads its trace in time order
    # One 64-byte transaction a line: a request of n bytes is ceil(n / 64) lines (a 20-byte hit
    # record write is one).
    rows = (run / "dram_requests.csv").read_text().splitlines()[1:]
    assert len(rows) == summary["requests"]
    assert len(lines) == sum(-(-int(r.split(",")[2]) // 64) for r in rows)
    assert {line.split()[1] for line in lines} <= {"READ", "WRITE"}


def test_dram_trace_needs_a_timed_level(
    cornell_small: Path,  # noqa: F811
    sim: Sim,  # noqa: F811
    tmp_path: Path,
) -> None:
    trace = cornell_small
    p = sim(trace, tmp_path / "run", "fidelity=analytic", extra=("--dram-trace", "--no-verdict"))
    assert p.returncode == 2
    assert "--dram-trace needs a timed level" in p.stderr


def test_conversions_to_dramsim3_clock_and_ramulator2(tmp_path: Path) -> None:
    m = dram_compare()
    core = tmp_path / "core.txt"
    core.write_text("0x40 READ 100\n0x1080 WRITE 250\n0x40 READ 1000\n")
    last, reads = m.to_memory_clock(core, tmp_path / "mc.txt", clock_ghz=2.0, tck_ns=0.5)
    # 2 GHz core cycles are 0.5 ns: one memory cycle of 0.5 ns each.
    assert (last, reads) == (1000, 2)
    assert (tmp_path / "mc.txt").read_text() == "0x40 READ 100\n0x1080 WRITE 250\n0x40 READ 1000\n"
    m.to_memory_clock(core, tmp_path / "mc1.txt", clock_ghz=1.0, tck_ns=0.94)
    assert (tmp_path / "mc1.txt").read_text().splitlines()[1] == "0x1080 WRITE 265"
    m.to_ramulator2(core, tmp_path / "ram.txt")
    assert (tmp_path / "ram.txt").read_text() == "LD 0x40\nST 0x1080\nLD 0x40\n"
    with pytest.raises(ValueError):
        m.parse_dramsim3_line("0x40 FETCH 3")


def test_dramsim3_config_takes_rtsims_channels(tmp_path: Path) -> None:
    m = dram_compare()
    base = tmp_path / "base.ini"
    base.write_text(
        "[dram_structure]\nBL = 8\n[timing]\ntCK = 0.94\nCL = 16\ntRCD = 16\n"
        "[system]\nchannels = 1\n[other]\noutput_level = 2\n"
    )
    ini = m.dramsim3_ini(base, 4, tmp_path / "out.ini")
    assert ini["system"]["channels"] == "4"
    assert "channels = 4" in (tmp_path / "out.ini").read_text()
    assert m.dramsim3_unloaded_ns(ini) == pytest.approx((16 + 16 + 4) * 0.94)


def test_closed_loop_moves_rtsims_latency_to_the_simulators_mean(
    cornell_small: Path,  # noqa: F811
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """scripts/dram_closed_loop.py against a stand-in simulator whose mean read latency is 400 ns
    whatever the stream: the loop raises rtsim's latency until rtsim's own mean on its stream is
    within the tolerance of it, and the slower memory costs the machine cycles."""
    path = REPO / "scripts" / "dram_closed_loop.py"
    spec = importlib.util.spec_from_file_location("dram_closed_loop", path)
    assert spec and spec.loader
    loop = importlib.util.module_from_spec(spec)
    sys.modules["dram_closed_loop"] = loop
    spec.loader.exec_module(loop)
    monkeypatch.setattr(loop, "replay", lambda *_: 400.0)
    args = argparse.Namespace(out=tmp_path, iterations=14, tolerance=0.03)
    r = loop.close_loop("cornell", cornell_small, 1, "dramsim3", args)
    last = r["best"]
    assert r["converged"] and abs(last["rtsim_ns"] - 400.0) <= 12.0
    assert 1 < len(r["steps"]) <= 14 and last["latency"] > r["steps"][0]["latency"]
    assert last["cycles"] > r["banks_cycles"]
    assert "| cornell | 1 | DRAMsim3 |" in loop.table([r])
