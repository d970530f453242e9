"""The DRAM-by-kind chart keeps every data kind a run moved: a grid's cells and primitive
references stacked with the rest, so the bars add up to the run's DRAM bytes per ray."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

from rtsim.report.figures import KIND_NAMES, kind_style, kinds_present


def test_structure_kinds_are_not_dropped() -> None:
    grid = {"cell": 900.0, "prim_ref": 317.0, "node": 0.0, "triangle": 1500.0, "ray": 69.0}
    bvh = {"node": 1200.0, "triangle": 1300.0, "ray": 40.0, "hit": 20.0}
    kinds = kinds_present([grid, bvh])
    assert set(kinds) == {"cell", "prim_ref", "triangle", "ray", "node", "hit"}
    assert kinds.index("node") < kinds.index("cell")  # the known order first
    # Every kind is drawn: the stacked total is the run's total.
    assert sum(grid[k] for k in kinds if k in grid) == sum(grid.values())
    # Named and coloured; a kind never seen before still gets a colour and a readable name.
    assert kind_style("cell", 0)[1] == KIND_NAMES["cell"]
    color, name = kind_style("mailbox_line", 7)
    assert color.startswith("#") and name == "mailbox line"
    assert "mailbox_line" in kinds_present([{"mailbox_line": 3.0}])


def test_log_axes_get_several_ticks() -> None:
    from rtsim.report.figures import log_ticks

    # Wide spans: powers of ten; two decades: 1-2-5 steps; a span inside one decade (40 to
    # 90) or narrower still gets several ticks.
    assert log_ticks(1.0, 1000.0) == [1.0, 10.0, 100.0, 1000.0]
    assert log_ticks(3.0, 120.0) == [5.0, 10.0, 20.0, 50.0, 100.0]
    for lo, hi in ((40.0, 90.0), (1500.0, 2600.0), (0.031, 0.047), (61.0, 64.0)):
        ticks = log_ticks(lo, hi)
        assert len(ticks) >= 2, (lo, hi, ticks)
        assert all(lo <= t <= hi for t in ticks), (lo, hi, ticks)
    assert log_ticks(0.0, 1.0) == []
