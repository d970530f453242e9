"""Energy and area in every run (docs/energy_area.md), presets from published machines and the
chosen defaults (docs/presets.md), end to end through rtsim-sim."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

import test_model
from rtsim.config import PRESETS, SimConfig, compose
from test_model import Sim

sim = test_model.sim
trace_of = test_model.trace_of
cornell_small = test_model.cornell_small

MACHINES = ("rtx2060", "rtx2080", "strata")


def stats_of(sim: Sim, trace: Path, out: Path, *sets: str, config: Path | None = None) -> Any:
    extra = ("--config", str(config)) if config else ()
    result = sim(trace, out, *sets, extra=extra)
    assert result.returncode == 0, result.stderr
    return json.loads((out / "stats.json").read_text())


@pytest.mark.parametrize("level", ["analytic", "approx", "detailed"])
def test_timed_levels_report_energy_and_area(
    sim: Sim, cornell_small: Path, tmp_path: Path, level: str
) -> None:
    stats = stats_of(sim, cornell_small, tmp_path, f"fidelity={level}")
    s, e = stats["summary"], stats["energy"]
    assert e["complete"] and e["missing"] == []
    parts = {k: v for k, v in e["per_ray_nj"].items() if k != "total"}
    assert all(v is not None and v >= 0 for v in parts.values()), parts
    assert s["energy_per_ray_nj"] == pytest.approx(sum(parts.values()))
    assert s["mrays_per_joule"] == pytest.approx(1e3 / s["energy_per_ray_nj"])
    assert s["power_w"] == pytest.approx(s["energy_per_ray_nj"] * 1e-9 * s["rays_per_second"])
    assert s["area_mm2"] == pytest.approx(sum(stats["area"]["mm2"].values()))
    # DRAM energy is exactly bytes x 8 x pJ/bit (GDDR6 by default).
    dram = stats["model"]["dram"]
    moved = (dram["read_bytes"] + dram["write_bytes"]) / e["rays"]
    assert e["per_ray_nj"]["dram"] == pytest.approx(moved * 8 * 7.5 / 1000)


def test_functional_level_reports_what_it_can(
    sim: Sim, cornell_small: Path, tmp_path: Path
) -> None:
    stats = stats_of(sim, cornell_small, tmp_path, "fidelity=functional")
    s, e = stats["summary"], stats["energy"]
    assert s["energy_per_ray_nj"] is None and s["power_w"] is None
    assert s["area_mm2"] > 0
    assert e["per_ray_nj"]["box"] > 0 and e["per_ray_nj"]["dram"] is None
    assert set(e["missing"]) == {"l1", "l2", "dram", "leakage"}


def test_energy_knobs_move_the_right_blocks(sim: Sim, cornell_small: Path, tmp_path: Path) -> None:
    base = stats_of(sim, cornell_small, tmp_path / "base")
    hbm = stats_of(sim, cornell_small, tmp_path / "hbm", "energy.dram_kind=hbm2")
    old = stats_of(sim, cornell_small, tmp_path / "45nm", "energy.node_nm=45")
    # HBM2 moves the same bytes for less energy; the arithmetic does not change.
    assert hbm["energy"]["per_ray_nj"]["dram"] < base["energy"]["per_ray_nj"]["dram"]
    assert hbm["energy"]["per_ray_nj"]["box"] == base["energy"]["per_ray_nj"]["box"]
    # An older node costs more energy and area; the timing is untouched.
    assert old["energy"]["per_ray_nj"]["box"] > 10 * base["energy"]["per_ray_nj"]["box"]
    assert old["summary"]["area_mm2"] > 10 * base["summary"]["area_mm2"]
    assert old["summary"]["cycles"] == base["summary"]["cycles"]


@pytest.mark.parametrize("name", MACHINES)
def test_machine_presets_run(name: str, sim: Sim, cornell_small: Path, tmp_path: Path) -> None:
    assert name in PRESETS
    config = tmp_path / "config.json"
    config.write_text(compose(name).to_json())
    stats = stats_of(sim, cornell_small, tmp_path / "run", config=config)
    assert stats["validation"]["hit_mismatches"] == 0
    resolved = json.loads((tmp_path / "run" / "config.resolved.json").read_text())
    assert resolved["traversal"]["units"] == compose(name).traversal.units
    # Each is a much bigger machine than the default (0.8 mm^2): more units, caches and area.
    assert stats["summary"]["area_mm2"] > 5


def test_turing_presets_scale_like_the_chips() -> None:
    r60, r80 = compose("rtx2060"), compose("rtx2080")
    assert (r60.traversal.units, r80.traversal.units) == (30, 46)
    peak = [c.dram.channels * c.dram.bytes_per_cycle * c.clock_ghz for c in (r60, r80)]
    assert peak[0] == pytest.approx(336, rel=0.03) and peak[1] == pytest.approx(448, rel=0.03)
    assert (r60.l2.size_kib, r80.l2.size_kib) == (3072, 4096)
    assert compose("strata").treelets.enabled


@pytest.mark.parametrize(
    "name, units, warps, mshrs, l2_kib, channels, bytes_per_cycle",
    [
        # docs/presets.md, "The Vulkan-Sim baseline": gpgpu_rt_max_warps, gpgpu_rt_max_mshr (or
        # the RT cache's MSHRs), the L2 and the GDDR6 channels of each Vulkan-Sim config.
        ("vulkansim_rtx2060", 30, 4, 64, 3072, 12, 20),
        ("vulkansim_mobile", 2, 16, 256, 256, 2, 10),
    ],
)
def test_vulkansim_presets_match_their_table(
    name: str,
    units: int,
    warps: int,
    mshrs: int,
    l2_kib: int,
    channels: int,
    bytes_per_cycle: int,
    sim: Sim,
    cornell_small: Path,
    tmp_path: Path,
) -> None:
    config = tmp_path / "config.json"
    config.write_text(compose(name).to_json())
    stats = stats_of(sim, cornell_small, tmp_path / "run", config=config)
    assert stats["validation"]["hit_mismatches"] == 0
    r = json.loads((tmp_path / "run" / "config.resolved.json").read_text())
    t = r["traversal"]
    assert (t["units"], t["model"], t["simt"]["lanes"], t["simt"]["refill"]) == (
        units,
        "simt",
        32,
        "warp",
    )
    assert t["ray_contexts"] == warps * 32
    assert r["l1"]["mshrs"] == mshrs and r["l1"]["size_kib"] == 64 and r["l1"]["line_bytes"] == 128
    assert r["l2"]["size_kib"] == l2_kib and r["clock_ghz"] == pytest.approx(1.365)
    assert (r["dram"]["channels"], r["dram"]["bytes_per_cycle"]) == (channels, bytes_per_cycle)
    assert stats["summary"]["simd_efficiency"] is not None


def test_defaults_give_each_context_an_mshr() -> None:
    # docs/presets.md, "How the defaults were chosen": at 8 L1 MSHRs for 16 contexts the L1s
    # starved Sponza diffuse (+30% from doubling them).
    c = SimConfig()
    assert c.l1.mshrs >= c.traversal.ray_contexts
    assert c.l2.mshrs >= c.traversal.units * 8


def test_machine_presets_compose_with_modifiers() -> None:
    c = compose("rtx2080+treelets+dram-2x")
    assert c.treelets.enabled and c.dram.bytes_per_cycle == 32 and c.traversal.units == 46
