"""The sweep report on a store holding two specs (docs/sweeps.md allows it): a MIMD spec over
traversal units and a SIMT spec over warp lanes, swept into one folder. Each defect once found is
checked here: the speed-up caption and the structures heading named the SIMT configuration while
the bars were the MIMD run's; the rays/s panel against traversal.model showed only SIMT; figure
legends overlapped the panels' titles and the roofline's hid points; the bytes-by-kind chart
folded the baseline into "(+N alike)"; and `baseline: {accel: LABEL}` was refused."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib
import pytest

matplotlib.use("Agg")

from matplotlib.figure import Figure

from rtsim.config import SimConfig
from rtsim.report import figures
from rtsim.report.data import load
from rtsim.report.html import render_report
from rtsim.sweep.runner import SPEC_SEPARATOR
from rtsim.sweep.spec import SpecError, parse_spec
from rtsim.sweep.store import RunRecord, open_store

MIMD_SPEC = """name: mimd
scenes: [cornell]
workloads: [{name: diffuse, rays: [diffuse], resolution: 8x8}]
grid: {traversal.units: [4, 8]}
"""
SIMT_SPEC = """name: simt
scenes: [cornell]
workloads: [{name: diffuse, rays: [diffuse], resolution: 8x8}]
grid: {traversal.model: [simt], traversal.simt.lanes: [8, 16]}
"""


def record(params: dict[str, Any], mrays: float, kinds: dict[str, float]) -> RunRecord:
    config = SimConfig().with_values(params).to_dict()
    dram = sum(kinds.values())
    stats = {
        "summary": {
            "rays": 1000,
            "rays_per_second": mrays * 1e6,
            "area_mm2": 1.0,
            "energy_per_ray_nj": 10.0,
            "l1_hit_rate": 0.5,
            "l2_hit_rate": 0.4,
            "dram_bytes_per_ray": dram,
        },
        "model": {"dram": {"by_kind": {k: {"read_bytes": v * 1000} for k, v in kinds.items()}}},
        "roofline": {
            "dram_bytes_per_ray": dram,
            "rays_per_second": mrays * 1e6,
            "peak_dram_bytes_per_second": 32e9,
            "ceilings": {"dram": 32e9 / dram, "box": 4e8},
            "bound": "box",
        },
    }
    rid = "-".join(f"{k}={v}" for k, v in params.items())
    return RunRecord(rid, "cornell", "diffuse", "t" * 16, "base", "ok", dict(params), config,
                     stats=stats)  # fmt: skip


def two_spec_store(tmp_path: Path) -> Path:
    """MIMD runs at 4 and 8 units (4 is the MIMD spec's baseline), SIMT runs at 8 and 16 lanes;
    all four move the same bytes per ray, so a chart merging alike runs would fold them."""
    same = {"node": 300.0, "triangle": 50.0}
    runs = [
        record({"traversal.units": 4}, 10.0, same),
        record({"traversal.units": 8}, 18.0, same),
        record({"traversal.model": "simt", "traversal.simt.lanes": 8}, 30.0, same),
        record({"traversal.model": "simt", "traversal.simt.lanes": 16}, 25.0, same),
    ]
    with open_store(tmp_path) as store:
        store.set_meta(
            {
                "name": "two specs",
                "spec": SPEC_SEPARATOR.join([MIMD_SPEC, SIMT_SPEC]),
                "swept_keys": "traversal.units,traversal.model,traversal.simt.lanes",
            }
        )
        for r in runs:
            store.record(r)
    return tmp_path


def test_baseline_is_one_specs_run_and_the_caption_names_it(tmp_path: Path) -> None:
    data = load(two_spec_store(tmp_path))
    base = data.baseline_run(data.groups()[0].ok)
    assert base is not None
    # The MIMD spec's baseline (4 units), not a SIMT run that lacks a traversal.units param.
    assert base.params == {"traversal.units": 4}
    fig = figures.speedup(data)
    assert fig is not None
    widths = sorted(p.get_width() for p in fig.axes[0].patches)
    assert widths[0] == pytest.approx(1.0)  # the baseline, slowest
    assert widths[-1] == pytest.approx(3.0)  # SIMT at 8 lanes over MIMD at 4 units
    html = render_report(data)
    caption = html.split("of each configuration over the baseline (")[1].split("</figcaption>")[0]
    assert data.label(base) in caption
    assert "simt" not in caption
    assert "model=mimd" in data.label(base)  # the run's own model, from its config
    assert "lanes" not in data.label(base)  # lanes are inactive under MIMD


def test_every_model_in_the_panel_against_traversal_model(tmp_path: Path) -> None:
    data = load(two_spec_store(tmp_path))
    assert set(data.values("traversal.model")) == {"mimd", "simt"}
    fig = figures.rays_per_second(data)
    assert fig is not None
    panel = next(a for a in fig.axes if "traversal.model" in a.get_title())
    ticks = [t.get_text() for t in panel.get_xticklabels()]
    assert set(ticks) == {"mimd", "simt"}


def overlaps(a: Any, b: Any) -> bool:
    return bool(a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1)


def legends_clear_of_titles(fig: Figure) -> None:
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
    legends = [*fig.legends, *(a.get_legend() for a in fig.axes if a.get_legend())]
    assert legends
    for legend in legends:
        box = legend.get_window_extent(renderer)
        for ax in fig.axes:
            if ax.get_visible() and ax.get_title():
                assert not overlaps(box, ax.title.get_window_extent(renderer)), ax.get_title()
            if ax.get_visible():
                # Nor inside a panel, where it would hide what the panel draws.
                assert not overlaps(box, ax.get_window_extent(renderer)), ax.get_title()


def test_legends_overlap_no_title_and_no_panel(tmp_path: Path) -> None:
    data = load(two_spec_store(tmp_path))
    for make in (figures.rays_per_second, figures.hit_rates, figures.roofline):
        fig = make(data)
        assert fig is not None, make.__name__
        legends_clear_of_titles(fig)
    fig, _ = figures.pareto(data, "area")
    assert fig is not None
    legends_clear_of_titles(fig)


def test_baseline_keeps_its_own_bar_in_bytes_by_kind(tmp_path: Path) -> None:
    data = load(two_spec_store(tmp_path))
    fig = figures.bytes_per_ray(data)
    assert fig is not None
    labels = [t.get_text() for t in fig.axes[0].get_yticklabels()]
    base = data.baseline_run(data.groups()[0].ok)
    assert base is not None
    assert any(data.label(base) in x and "(baseline)" in x for x in labels)
    # The other three, alike, are one bar; the baseline is not among them.
    folded = [x for x in labels if "alike" in x]
    assert len(folded) == 1 and "(+2 alike)" in folded[0]


def test_baseline_names_a_structure_of_the_accel_axis() -> None:
    text = """
scenes: [cornell]
workloads: [{name: p, rays: [primary], resolution: 8x8}]
accel: [bvh2, {kind: bvh8, label: wide}]
grid: {traversal.units: [4, 16]}
baseline: {accel: wide}
"""
    assert parse_spec(text).baseline == {"accel": "wide"}
    with pytest.raises(SpecError, match="not one of the accel axis"):
        parse_spec(text.replace("{accel: wide}", "{accel: nosuch}"))
    with pytest.raises(SpecError, match="no accel axis"):
        parse_spec(text.replace("accel: [bvh2, {kind: bvh8, label: wide}]\n", ""))
