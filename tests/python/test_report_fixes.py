"""Report defects once found, on synthetic runs: categorical keys split marginal lines,
speed-up over a named baseline, powers of two on log axes, no ray-buffer size on treelets-off
labels, Pareto fronts against area and energy, heatmap clipping and panels, the accuracy legend,
and `rtsim results` key columns for stores that mix specs."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

from rtsim import heatmaps
from rtsim.accuracy import Row, accuracy_figure
from rtsim.config import SimConfig
from rtsim.report import figures
from rtsim.report.data import SweepData, pareto_front, spec_baseline
from rtsim.sweep.results import key_value
from rtsim.sweep.spec import SpecError, parse_spec
from rtsim.sweep.store import RunRecord


def run(params: dict[str, Any], mrays: float, area: float = 1.0, nj: float = 10.0) -> RunRecord:
    config = SimConfig().with_values(params).to_dict()
    stats = {
        "summary": {
            "rays_per_second": mrays * 1e6,
            "area_mm2": area,
            "energy_per_ray_nj": nj,
            "l1_hit_rate": 0.5,
            "l2_hit_rate": 0.5,
            "dram_bytes_per_ray": 100.0,
        }
    }
    rid = "-".join(f"{k}={v}" for k, v in params.items())
    return RunRecord(rid, "hairball", "diffuse", "t" * 16, "base", "ok", dict(params), config,
                     stats=stats)  # fmt: skip


def treelet_sweep() -> SweepData:
    """Treelets off are 4x slower than on at every L1 size: a median over both would lie."""
    runs = []
    for l1 in (16, 32, 64):
        for on in (False, True):
            for rb in (512, 2048):
                speed = (40.0 if on else 10.0) + l1 / 16
                params = {"l1.size_kib": l1, "treelets.enabled": on, "treelets.buffer_kib": rb}
                runs.append(run(params, speed))
    keys = ["l1.size_kib", "treelets.enabled", "treelets.buffer_kib"]
    base = {"l1.size_kib": 16, "treelets.enabled": False, "treelets.buffer_kib": 512}
    return SweepData(Path("."), {}, keys, runs, base)


def lines_of(ax: Any) -> dict[str, list[float]]:
    return {
        line.get_label(): list(line.get_ydata())
        for line in ax.get_lines()
        if not line.get_label().startswith("_")
    }


def test_marginal_plot_splits_categorical_keys() -> None:
    data = treelet_sweep()
    fig = figures.rays_per_second(data)
    assert fig is not None
    ax = fig.axes[0]  # rays/s against l1.size_kib
    lines = lines_of(ax)
    assert set(lines) == {"diffuse · no treelets", "diffuse · treelets"}
    # Each line is one machine: treelets off ~11-14, on ~41-44 (a mixed median would be ~25).
    assert max(lines["diffuse · no treelets"]) < 15
    assert min(lines["diffuse · treelets"]) > 40


def test_treelets_off_label_has_no_buffer_size() -> None:
    data = treelet_sweep()
    off = next(r for r in data.runs if not r.params["treelets.enabled"])
    on = next(r for r in data.runs if r.params["treelets.enabled"])
    assert "RB" not in data.label(off)
    assert "no treelets" in data.label(off)
    assert "RB" in data.label(on)


def test_speedup_over_named_baseline() -> None:
    data = treelet_sweep()
    base = data.baseline_run(data.runs)
    assert base is not None and base.params["l1.size_kib"] == 16
    assert not base.params["treelets.enabled"]
    fig = figures.speedup(data)
    assert fig is not None
    widths = [p.get_width() for p in fig.axes[0].patches]
    assert min(widths) == pytest.approx(1.0)  # the baseline is the slowest here
    assert max(widths) == pytest.approx(44.0 / 11.0)


def test_spec_baseline_is_checked_and_read() -> None:
    text = """
scenes: [cornell]
workloads: [{name: p, rays: [primary], resolution: 8x8}]
grid: {traversal.units: [4, 16], treelets.enabled: [false, true]}
baseline: {treelets.enabled: true}
"""
    assert parse_spec(text).baseline == {"treelets.enabled": True}
    assert spec_baseline(text, [], ["traversal.units", "treelets.enabled"]) == {
        "traversal.units": 4,
        "treelets.enabled": True,
    }
    with pytest.raises(SpecError, match=r"baseline\.l1\.size_kib"):
        parse_spec(text.replace("treelets.enabled: true}", "l1.size_kib: 64}"))
    with pytest.raises(SpecError, match="not one of"):
        parse_spec(text.replace("{treelets.enabled: true}", "{traversal.units: 8}"))


def test_powers_of_two_on_log_axis() -> None:
    runs = [run({"l1.size_kib": v}, 10.0 + v) for v in (4, 8, 16, 32, 64, 128, 256, 512, 1024)]
    data = SweepData(Path("."), {}, ["l1.size_kib"], runs, {"l1.size_kib": 4})
    fig = figures.rays_per_second(data)
    assert fig is not None
    ax = fig.axes[0]
    assert ax.get_xscale() == "log"
    fig.canvas.draw()
    labels = [t.get_text() for t in ax.get_xticklabels() if t.get_text()]
    assert "64" in labels and "1024" in labels, labels
    assert not any("^" in label for label in labels), labels  # never 2^6


def test_pareto_fronts_against_area_and_energy() -> None:
    # Fast but large and hungry, slow but small and frugal, and one beaten on every axis.
    runs = [
        run({"l1.size_kib": 64}, 50.0, area=4.0, nj=30.0),
        run({"l1.size_kib": 16}, 20.0, area=1.0, nj=10.0),
        run({"l1.size_kib": 32}, 15.0, area=2.0, nj=20.0),
    ]
    data = SweepData(Path("."), {}, ["l1.size_kib"], runs, {})
    for cost in ("area", "energy"):
        fig, fronts = figures.pareto(data, cost)
        assert fig is not None
        front = fronts["hairball / diffuse"]
        assert [r.params["l1.size_kib"] for r in front] == [16, 64], cost
    # A store from before the energy model (no area): nothing to draw, no crash.
    old = run({"l1.size_kib": 8}, 5.0)
    old.stats["summary"].pop("area_mm2")  # type: ignore[index]
    assert pareto_front([old], lambda r: r.summary.get("area_mm2")) == []


def test_results_key_columns_never_blank() -> None:
    # Two specs in one store: one swept l1.size_kib, the other traversal.units.
    a = run({"l1.size_kib": 64}, 10.0)
    b = run({"traversal.units": 16}, 10.0)
    assert key_value(a, "l1.size_kib") == (64, True)
    assert key_value(b, "l1.size_kib") == (16, False)  # the default it ran with
    assert key_value(a, "traversal.units") == (8, False)
    assert key_value(a, "preset") == ("base", False)


def work(primary: np.ndarray, all_rays: np.ndarray, n_primary: int, n_other: int) -> Any:
    return heatmaps.PixelWork("tri_tests", primary, all_rays, n_primary, n_other)


def test_heatmap_scale_clips_outliers() -> None:
    data = np.full((40, 40), 10.0)
    data[0, 0] = 1e6  # one grazing pixel
    assert heatmaps.color_limit(data) < 100  # linear to the max would make the rest black
    assert heatmaps.color_limit(np.zeros((4, 4))) == 1.0


def test_heatmap_panels_follow_the_rays_present() -> None:
    z = np.zeros((2, 2))
    assert [t for _, t in heatmaps.panels(work(z, z + 1, 0, 4))] == ["all rays (no primary rays)"]
    assert [t for _, t in heatmaps.panels(work(z + 1, z + 1, 4, 0))] == [
        "primary rays (the only kind)"
    ]
    assert len(heatmaps.panels(work(z + 1, z + 2, 4, 4))) == 2


def test_accuracy_legend_fits_with_one_panel() -> None:
    common = {"scene": "cornell", "workload": "primary", "rays": 100, "reference": "detailed"}
    rows = [
        Row(level="approx", fraction=None, wall_seconds=0.1, error=0.02, **common),
        Row(level="detailed", fraction=None, wall_seconds=0.3, error=0.0, **common),
    ]
    fig = accuracy_figure(rows)
    fig.canvas.draw()
    legend = fig.legends[0].get_window_extent()
    box = fig.bbox
    assert legend.x0 >= box.x0 - 1 and legend.x1 <= box.x1 + 1
    assert legend.y0 >= box.y0 - 1
