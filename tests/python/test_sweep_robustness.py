"""Sweeps under hostile conditions: a grid too big to enumerate, two sweeps on one
folder, and the unfinished trace folders a killed sweep leaves behind."""

from __future__ import annotations

import time
from pathlib import Path

import pytest
from rich.console import Console

from rtsim.cli import main
from rtsim.sweep import runner
from rtsim.sweep.lock import SweepLockedError, clean_stale_traces, sweep_lock
from rtsim.sweep.runner import SweepOptions, SweepOutcome, run_sweep
from rtsim.sweep.spec import MAX_RUNS, SpecError, parse_spec

SMALL = """\
scenes: [cornell]
workloads: [{rays: [primary], resolution: 8x8}]
grid:
  traversal.units: [1, 2]
"""

# 6 keys x 30 values: 729,000,000 points.
HUGE = "scenes: [cornell]\nworkloads: [{rays: [primary], resolution: 8x8}]\ngrid:\n" + "".join(
    f"  {key}: [{', '.join(str(v) for v in range(1, 31))}]\n"
    for key in (
        "traversal.units",
        "traversal.ray_contexts",
        "l1.latency",
        "l2.latency",
        "box.latency",
        "triangle.latency",
    )
)


def test_huge_grid_refused_before_enumerating() -> None:
    t0 = time.monotonic()
    with pytest.raises(SpecError) as info:
        parse_spec(HUGE, source="huge.yaml")
    message = str(info.value)
    assert message.startswith("huge.yaml:3: grid: 729,000,000 runs"), message
    assert f"limit of {MAX_RUNS:,} runs" in message
    assert time.monotonic() - t0 < 5  # refused from the sizes, not by listing points


def test_huge_sampling_refused() -> None:
    text = SMALL.replace("grid:\n  traversal.units: [1, 2]\n", "") + (
        "sampling:\n  n: 1000000000\n  ranges:\n    l1.size_kib: [8, 64]\n"
    )
    with pytest.raises(SpecError, match=r"1,000,000,000 runs"):
        parse_spec(text, source="s.yaml")


def test_huge_grid_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = tmp_path / "huge.yaml"
    spec.write_text(HUGE)
    assert main(["sweep", str(spec), "-o", str(tmp_path / "out"), "--no-progress"]) == 2
    assert "huge.yaml:3: grid: 729,000,000 runs" in capsys.readouterr().err


def test_second_sweep_on_a_folder_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = tmp_path / "small.yaml"
    spec.write_text(SMALL)
    out = tmp_path / "out"
    out.mkdir()
    with sweep_lock(out):
        code = main(["sweep", str(spec), "-o", str(out), "--no-progress"])
        err = " ".join(capsys.readouterr().err.split())
    assert code == 2, err
    assert f"{out}: another sweep is running on this folder (pid " in err
    assert not (out / "results.sqlite").exists()  # refused before touching the store
    # Released when the holder is done: the folder can be locked again.
    with sweep_lock(out):
        pass


def test_lock_is_exclusive_and_names_the_holder(tmp_path: Path) -> None:
    with (
        sweep_lock(tmp_path),
        pytest.raises(SweepLockedError, match=r"pid \d+ on "),
        sweep_lock(tmp_path),
    ):
        pass


def test_stale_trace_folders_removed_when_a_sweep_starts(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    traces = tmp_path / "traces"
    stale = traces / "cornell-primary-abc.tmp-host-4242"
    stale.mkdir(parents=True)
    (stale / "trace.rtt").write_bytes(b"partial")
    kept = traces / "cornell-primary-abc"
    kept.mkdir()
    seen: list[bool] = []

    def fake_run(spec: object, opts: object, out: Path, console: Console) -> SweepOutcome:
        seen.append(stale.exists())  # cleaned before any run starts
        return SweepOutcome(total=0, skipped=0)

    monkeypatch.setattr(runner, "_run_locked", fake_run)
    run_sweep(parse_spec(SMALL, "s.yaml"), SweepOptions(out_dir=tmp_path), Console(quiet=True))
    assert seen == [False]
    assert kept.is_dir()
    assert clean_stale_traces(tmp_path / "nowhere") == []
