"""Hostile paths, stores, specs and configs through the command line: every case exits 2 with a
message naming the file (or key) and what to change; none leaves a traceback, blocks or reads
without end."""

from __future__ import annotations

import os
import sqlite3
import subprocess
import time
from pathlib import Path

import pytest

from rtsim.cli import main
from rtsim.launcher import find_sim

NON_UTF8 = os.fsdecode(b"out-\xff\xfe")  # a name a Latin-1 shell could make


def _err(capsys: pytest.CaptureFixture[str]) -> str:
    return " ".join(capsys.readouterr().err.split())  # the console may wrap long lines


def _exit_code(args: list[str]) -> int:
    try:
        return main(args)
    except SystemExit as e:  # argparse's own refusals
        return int(e.code or 0)


@pytest.mark.parametrize("where", ["non_utf8", "a_file", "proc"])
def test_trace_output_path_refused(where: str, tmp_path: Path, capsys) -> None:
    out = {"non_utf8": tmp_path / NON_UTF8, "a_file": tmp_path / "f", "proc": Path("/proc/rtsim")}[
        where
    ]
    if where == "a_file":
        out.write_text("x")
    code = main(["trace", "cornell", "-o", str(out), "--resolution", "8x8"])
    err = _err(capsys)
    assert code == 2, err
    fragment = {
        "non_utf8": "not valid UTF-8",
        "a_file": "is a file, not a folder",
        "proc": "cannot",
    }
    assert fragment[where] in err and "Traceback" not in err, err
    if where == "non_utf8":
        assert not (tmp_path / NON_UTF8).exists()  # refused before tracing


def test_sweep_output_path_not_utf8_refused(tmp_path: Path, capsys) -> None:
    (tmp_path / "s.yaml").write_text(SPEC)
    out = tmp_path / NON_UTF8
    code = main(["sweep", str(tmp_path / "s.yaml"), "-o", str(out), "--no-progress"])
    err = _err(capsys)
    assert code == 2 and "not valid UTF-8" in err, err
    assert not out.exists()


@pytest.mark.parametrize("where", ["non_utf8", "a_file", "proc"])
def test_sim_output_path_refused(where: str, cornell_trace: Path, tmp_path: Path) -> None:
    out = {
        "non_utf8": os.fsencode(str(tmp_path / NON_UTF8)),
        "a_file": str(tmp_path / "f"),
        "proc": "/proc/rtsim-run",
    }[where]
    if where == "a_file":
        Path(out).write_text("x")
    sim = subprocess.run(
        [os.fsencode(str(find_sim())), os.fsencode(str(cornell_trace)), b"-o", os.fsencode(out)],
        capture_output=True,
        timeout=60,
        check=False,
    )
    err = sim.stderr.decode("utf-8", "replace")
    assert sim.returncode == 2 and "rtsim-sim: error: " in err and "E549" not in err, err


def _store(kind: str, path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    if kind == "random":
        path.write_bytes(os.urandom(4096))
    elif kind == "foreign":
        with sqlite3.connect(path) as conn:
            conn.execute("CREATE TABLE photos (id INTEGER, name TEXT)")
    elif kind == "empty":
        path.write_bytes(b"")
    elif kind == "folder":  # SQLite's "unable to open database file" traceback before
        path.mkdir()
    else:  # a real store cut in the middle
        with sqlite3.connect(path) as conn:
            conn.execute("CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT)")
            conn.execute("CREATE TABLE runs (run_id TEXT PRIMARY KEY, stats_json TEXT)")
            conn.executemany(
                "INSERT INTO runs VALUES (?, ?)", [(str(i), "x" * 900) for i in range(200)]
            )
        data = path.read_bytes()
        path.write_bytes(data[: len(data) // 2 + 100])


SPEC = "scenes: [cornell]\nworkloads: [{rays: [primary], resolution: 8x8}]\n"


@pytest.mark.parametrize("kind", ["random", "foreign", "truncated", "folder"])
@pytest.mark.parametrize("command", ["results", "report", "sweep"])
def test_bad_results_store(kind: str, command: str, tmp_path: Path, capsys) -> None:
    sweep = tmp_path / "sweep"
    _store(kind, sweep / "results.sqlite")
    if command == "sweep":
        (tmp_path / "s.yaml").write_text(SPEC)
        args = ["sweep", str(tmp_path / "s.yaml"), "-o", str(sweep), "--no-progress"]
    else:
        args = [command, str(sweep)] + (
            ["-o", str(tmp_path / "r.html")] if command == "report" else []
        )
    code = _exit_code(args)
    err = _err(capsys)
    assert code == 2, err
    assert str(sweep / "results.sqlite") in err and "Traceback" not in err, err


DEEP_YAML = SPEC + "grid:\n  l1.size_kib: " + "[" * 50_000 + "]" * 50_000 + "\n"


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        (SPEC + "sampling:\n  n: 4\n  ranges:\n    l1.size_kib: {values: []}\n", "empty list"),
        (SPEC + "grid:\n  l1.size_kib: []\n", "non-empty list"),
        (DEEP_YAML, "nested too deeply"),
        (SPEC + "grid:\n  clock_ghz: [.nan]\n", "finite number"),
        (SPEC + "grid:\n  clock_ghz: [1.0, .inf]\n", "finite number"),
        (SPEC + "timeout: .nan\n", "timeout"),
        (SPEC + "timeout: .inf\n", "timeout"),
        (SPEC + "timeout: 0\n", "timeout"),
        ("scenes: [cornell]\nworkloads: [{resolution: 100000x100000}]\n", "pixels"),
        ("scenes: [cornell]\nworkloads: [{bounces: 1000}]\n", "bounces"),
        ("scenes: [missing/none.glb]\nworkloads: [{}]\n", "no such file"),
        ("scenes: [{name: cornell, seed: .inf}]\nworkloads: [{}]\n", "seed"),
    ],
    ids=lambda v: v if len(v) < 30 else None,
)
def test_bad_spec_refused_at_the_check(text: str, fragment: str, tmp_path: Path, capsys) -> None:
    spec = tmp_path / "bad.yaml"
    spec.write_text(text)
    t0 = time.monotonic()
    code = main(["sweep", str(spec), "-o", str(tmp_path / "out"), "--no-progress"])
    err = _err(capsys)
    assert code == 2, err
    assert str(spec) in err and fragment in err and "Traceback" not in err, err
    assert not (tmp_path / "out" / "results.sqlite").exists()  # no run attempted
    assert time.monotonic() - t0 < 30


@pytest.mark.parametrize("kind", ["fifo", "dev_zero", "non_utf8_text", "deep", "folder"])
def test_bad_config_file(kind: str, cornell_trace: Path, tmp_path: Path, capsys) -> None:
    config = tmp_path / "cfg.json"
    if kind == "fifo":
        os.mkfifo(config)
    elif kind == "dev_zero":
        config = Path("/dev/zero")
    elif kind == "non_utf8_text":
        config.write_bytes(b'{"clock_ghz": "\xff"}')
    elif kind == "deep":
        config.write_text("[" * 100_000 + "]" * 100_000)
    else:
        config.mkdir()
    t0 = time.monotonic()
    code = main(
        [
            "simulate",
            str(cornell_trace),
            "-o",
            str(tmp_path / "run"),
            "--config",
            str(config),
            "--no-progress",
        ]
    )
    err = _err(capsys)
    assert code == 2 and str(config) in err and "Traceback" not in err, err
    assert time.monotonic() - t0 < 30


def test_range_error_names_the_config_file(cornell_trace: Path, tmp_path: Path) -> None:
    config = tmp_path / "big.json"
    config.write_text('{"sampling": {"count": 2147483648}}')
    sim = subprocess.run(
        [str(find_sim()), str(cornell_trace), "-o", str(tmp_path / "run"), "--config", str(config)],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert sim.returncode == 2
    assert (
        f"{config}: config: 'sampling.count' = 2147483648 is out of range [0, 2147483647]"
        in sim.stderr
    )
    assert "e+09" not in sim.stderr, sim.stderr


def test_analytic_functional_caches_memory_refused(cornell_trace: Path, tmp_path: Path) -> None:
    sim = subprocess.run(
        [
            str(find_sim()),
            str(cornell_trace),
            "-o",
            str(tmp_path / "run"),
            "--set",
            "fidelity=analytic",
            "--set",
            "analytic.caches=functional",
            "--set",
            "traversal.units=4096",
            "--set",
            "traversal.ray_contexts=4096",
        ],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert sim.returncode == 2, sim.stderr
    assert "analytic.caches=functional" in sim.stderr and "GiB of host memory" in sim.stderr
    assert "16777216 ray contexts" in sim.stderr


def test_progress_display_is_bounded() -> None:
    """An animated trace reports thousands of stages; the display keeps the last few bars, so
    its cost per stage stays constant (it grew with every stage: 1,000 stages took 236 s)."""
    from io import StringIO

    from rich.console import Console

    from rtsim.progress import TraceProgress

    bar = TraceProgress(console=Console(file=StringIO()))
    t0 = time.monotonic()
    with bar:
        for f in range(300):
            for depth in ("primary", "depth 1"):
                bar(0, 10, f"frame {f} {depth}")
                bar(10, 10, f"frame {f} {depth}")
    assert len(bar._progress.tasks) == TraceProgress.MAX_BARS
    assert time.monotonic() - t0 < 20  # about 2 s


def test_trace_of_1024_frames_is_fast(tmp_path: Path) -> None:
    from conftest import rtsim_trace

    t0 = time.monotonic()
    rtsim_trace(
        "grove",
        "-o",
        str(tmp_path / "g"),
        "--frames",
        "1024",
        "--resolution",
        "4x3",
        "--workload",
        "primary",
    )
    assert time.monotonic() - t0 < 60  # 90 s before the display was bounded
