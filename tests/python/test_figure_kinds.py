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


def test_heatmap_colour_bar_label_fits_and_says_per_pixel() -> None:
    import numpy as np

    from rtsim.heatmaps import PixelWork, heatmap_figure

    rng = np.random.default_rng(1)
    data = rng.integers(0, 200, size=(96, 128)).astype(float)
    data[0, 0] = 5000.0  # an extreme pixel: the scale is clipped and says so
    work = PixelWork("steps", data / 3, data, 100, 200)
    label = "traversal steps (nodes or cells visited)"
    fig = heatmap_figure(work, label, "Sponza")
    fig.canvas.draw()
    box = fig.bbox
    texts = [t for ax in fig.axes for t in (ax.yaxis.label, ax.title) if t.get_text()]
    assert any("clipped" in t.get_text() for t in texts)
    for t in texts:
        extent = t.get_window_extent()
        assert extent.x0 >= box.x0 - 1 and extent.x1 <= box.x1 + 1, t.get_text()
        assert extent.y0 >= box.y0 - 1 and extent.y1 <= box.y1 + 1, t.get_text()
    titles = [ax.get_title() for ax in fig.axes if ax.get_title()]
    assert titles and all("per pixel" in t and "per ray" not in t for t in titles)


def test_figure_legend_names_every_panels_lines() -> None:
    import matplotlib.pyplot as plt

    from rtsim.report.figures import _fig_legend

    fig, (a, b) = plt.subplots(1, 2)
    a.plot([1, 2], [1, 2], label="diffuse")
    b.plot([1, 2], [2, 1], label="diffuse")
    b.plot([1, 2], [3, 3], label="diffuse · treelets on")  # only the second panel has it
    _fig_legend(fig)
    [legend] = fig.legends
    assert [t.get_text() for t in legend.get_texts()] == ["diffuse", "diffuse · treelets on"]
    plt.close(fig)
