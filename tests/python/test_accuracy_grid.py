"""`rtsim accuracy --spec` (python/rtsim/accuracy_grid.py): rank agreement and a small grid.

The measures on hand-made numbers (Kendall tau-b, the largest misordered gap, the Pareto front of
cycles against area), then one small grid end to end: every configuration at two levels, every
run checked against the reference hits, and the table, JSON and figure written.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from rtsim.accuracy_grid import (
    GridRow,
    by_point_markdown,
    compare,
    kendall_tau,
    largest_misordered_gap,
    pareto_front,
    summarize_grid,
)


def test_kendall_tau_on_known_rankings() -> None:
    assert kendall_tau([1, 2, 3, 4], [10, 20, 30, 40]) == 1.0
    assert kendall_tau([1, 2, 3, 4], [40, 30, 20, 10]) == -1.0
    # One swapped pair of six: (5 - 1) / 6.
    assert kendall_tau([1, 2, 3, 4], [1, 3, 2, 4]) == pytest.approx(4 / 6)
    assert kendall_tau([1], [1]) is None


def test_largest_misordered_gap_is_the_reference_gap_of_the_worst_swap() -> None:
    assert largest_misordered_gap([100, 200, 300], [1, 2, 3]) == 0.0
    # 100 and 101 swapped (1%), 200 and 300 in order.
    assert largest_misordered_gap([100, 101, 200, 300], [2, 1, 3, 4]) == pytest.approx(0.01)
    # 100 and 200 swapped: 100%.
    assert largest_misordered_gap([100, 101, 200], [3, 1, 2]) == pytest.approx(1.0)


def test_pareto_front_keeps_what_nothing_beats_on_both() -> None:
    points = {
        "fast_big": (100.0, 9.0),
        "slow_small": (300.0, 1.0),
        "mid": (200.0, 5.0),
        "bad": (250.0, 6.0),
    }
    assert pareto_front(points) == {"fast_big", "slow_small", "mid"}
    # Equal points do not beat each other.
    assert pareto_front({"a": (1.0, 1.0), "b": (1.0, 1.0)}) == {"a", "b"}


def row(level: str, point: str, cycles: float, area: float) -> GridRow:
    return GridRow("t", point, level, cycles=cycles, area_mm2=area, wall_seconds=1.0)


def test_summary_of_a_level_that_swaps_two_near_ties() -> None:
    rows = [
        row("detailed", p, c, a) for p, c, a in (("a", 1000, 1), ("b", 1001, 2), ("c", 2000, 0.5))
    ]
    rows += [
        row("approx", p, c, a) for p, c, a in (("a", 1010, 1), ("b", 1005, 2), ("c", 1900, 0.5))
    ]
    compare(rows)
    (approx,) = [s for s in summarize_grid(rows) if s["level"] == "approx"]
    assert approx["points"] == 3
    assert approx["max_abs_error"] == pytest.approx(0.05)
    assert approx["kendall_tau"] == pytest.approx(1 / 3)
    assert approx["largest_misordered_gap"] == pytest.approx(0.001)
    assert approx["same_best"] is False  # b is fastest at approx, a at detailed
    assert approx["same_pareto_front"] is False  # b joins the front at approx


def test_small_grid_end_to_end(
    tmp_path: Path, sim_exe: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from rich.console import Console

    from rtsim.accuracy_grid import run_grid

    monkeypatch.setenv("RTSIM_SIM", str(sim_exe))
    spec = tmp_path / "small.yaml"
    spec.write_text(
        "name: small\nscenes: [cornell]\n"
        "workloads:\n  - {name: primary, rays: [primary], resolution: 32x24}\n"
        "grid:\n  traversal.units: [2, 4]\n  dram.bytes_per_cycle: [4, 16]\n"
    )
    out = tmp_path / "grid"
    rows = run_grid(spec, out, ["approx", "detailed"], Console(quiet=True))
    assert len(rows) == 8
    assert all(r.status == "ok" and r.hit_mismatches == 0 and r.cycles for r in rows)
    summary = json.loads((out / "grid.json").read_text())["summary"]
    (approx,) = [s for s in summary if s["level"] == "approx"]
    assert approx["points"] == 4 and approx["max_abs_error"] < 0.15
    assert approx["same_pareto_front"] is not None
    assert "largest misordered gap" in (out / "grid.md").read_text()
    assert (out / "grid.png").stat().st_size > 0


def test_figure_with_more_traces_than_markers(tmp_path: Path) -> None:
    from rtsim.accuracy_grid import plot_grid

    rows = []
    for t in range(10):  # more traces than the figure has marker shapes
        rows += [row("detailed", "p", 100.0 + t, 1.0), row("approx", "p", 101.0 + t, 1.0)]
        rows[-1].trace = rows[-2].trace = f"trace{t}"
    plot_grid(rows, tmp_path / "grid.png")
    assert (tmp_path / "grid.png").stat().st_size > 0


def test_by_point_table_groups_errors_by_named_point() -> None:
    # A spec with named points: each level's rows grouped by the point's label, over its traces.
    rows = [
        GridRow(
            "t1", "dram.bytes_per_cycle=8 point=simt8 traversal.model=simt", "analytic", error=0.04
        ),
        GridRow(
            "t2",
            "dram.bytes_per_cycle=16 point=simt8 traversal.model=simt",
            "analytic",
            error=-0.02,
        ),
        GridRow("t1", "dram.bytes_per_cycle=8 point=mimd", "analytic", error=-0.10),
        GridRow("t1", "dram.bytes_per_cycle=8 point=mimd", "detailed", error=0.0),
    ]
    lines = by_point_markdown(rows).splitlines()
    assert len(lines) == 4  # header, rule, simt8, mimd: the reference level is left out
    assert lines[2].startswith("| analytic | simt8 | 2 | +1.0% | -2.0% / +4.0% | 4.0% |")
    assert lines[3].startswith("| analytic | mimd | 1 | -10.0%")


def test_grid_overrides_reach_every_run(
    tmp_path: Path, sim_exe: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # `rtsim accuracy --spec ... --set KEY=VALUE` overrides every run of the grid (it was once
    # dropped silently with --spec); the level's own fidelity still wins.
    from rich.console import Console

    from rtsim.accuracy_grid import run_grid

    monkeypatch.setenv("RTSIM_SIM", str(sim_exe))
    spec = tmp_path / "one.yaml"
    spec.write_text(
        "name: one\nscenes: [cornell]\n"
        "workloads:\n  - {name: primary, rays: [primary], resolution: 16x12}\n"
        "grid:\n  traversal.units: [2]\n"
    )
    out = tmp_path / "grid"
    rows = run_grid(spec, out, ["approx"], Console(quiet=True), ["quantum_cycles=32"])
    assert [r.status for r in rows] == ["ok"]
    (resolved,) = out.glob("runs/*/*/approx/config.resolved.json")
    config = json.loads(resolved.read_text())
    assert config["quantum_cycles"] == 32 and config["fidelity"] == "approx"
