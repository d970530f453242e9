"""Treelet prefetching (Chou, Nowicki & Aamodt 2023; docs/treelets.md, "Prefetching"): it
changes no hit and no reference work count, every prefetched line is accounted for exactly once
(issued = useful + useless + still resident), the lines the units send all reach their target,
off means no prefetch stats at all, and its config fields are checked by name."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from conftest import rtsim_trace, sim_or_fail, sim_stats, simulate

TREELETS = ("treelets.enabled=true", "treelets.buffer_kib=256", "l2.size_kib=128")


@pytest.fixture(scope="module")
def hairball_diffuse(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("prefetch") / "hairball_diffuse"
    rtsim_trace(
        "hairball", "-o", str(out), "--workload", "diffuse",
        "--resolution", "128x96", "--hairball-triangles", "20000",
    )  # fmt: skip
    return out


@pytest.fixture(scope="module")
def without(hairball_diffuse: Path, tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    return sim_stats(
        sim_or_fail(), hairball_diffuse, tmp_path_factory.mktemp("off") / "r", *TREELETS
    )


def caches(stats: dict[str, Any]) -> list[dict[str, Any]]:
    return [*stats["model"]["l1"].values(), stats["model"]["l2"]]


def test_off_writes_no_prefetch_stats(without: dict[str, Any]) -> None:
    assert all("prefetch" not in c for c in caches(without))
    assert "prefetch" not in without["model"]["ray_buffer"]
    assert all("prefetch" not in u for u in without["model"]["units"].values())


@pytest.mark.parametrize(("into", "lines"), [("l1", 0), ("l1", 4), ("l2", 0)])
def test_prefetch_changes_no_hit_or_work_and_adds_up(
    hairball_diffuse: Path, tmp_path: Path, without: dict[str, Any], into: str, lines: int
) -> None:
    stats = sim_stats(
        sim_or_fail(), hairball_diffuse, tmp_path / "run", *TREELETS, "treelets.prefetch=true",
        f"treelets.prefetch_into={into}", f"treelets.prefetch_lines={lines}",
    )  # fmt: skip
    validation = stats["validation"]
    assert validation["hit_mismatches"] == 0 and validation["work_mismatches"] == 0
    assert validation["rays_checked"] == without["validation"]["rays_checked"]
    # The same traversal: as many steps and treelet changes as without prefetching.
    units, units_off = stats["model"]["units"], without["model"]["units"]
    assert sum(u["steps"] for u in units.values()) == sum(u["steps"] for u in units_off.values())
    assert stats["model"]["ray_buffer"]["parked"] == without["model"]["ray_buffer"]["parked"]
    # Every prefetched line is counted once at its target.
    targets = list(stats["model"]["l1"].values()) if into == "l1" else [stats["model"]["l2"]]
    issued = 0
    for cache in targets:
        pf = cache["prefetch"]
        assert pf["issued"] == pf["useful"] + pf["useless"] + pf["resident"], pf
        assert pf["late"] <= pf["useful"]
        assert pf["below_bytes"] == pf["issued"] * cache["config"]["line_bytes"]
        issued += pf["issued"]
    sent = sum(u["prefetch"]["sent"] for u in units.values())
    assert sent == issued + sum(c["prefetch"]["redundant"] for c in targets)
    assert issued > 0 and sum(c["prefetch"]["useful"] for c in targets) > 0
    if lines:
        entries = sum(u["prefetch"]["entries"] for u in units.values())
        assert sum(u["prefetch"]["queued"] for u in units.values()) <= lines * entries
    table = stats["model"]["ray_buffer"]["prefetch"]
    assert 0 < table["treelets_learnt"] <= stats["model"]["ray_buffer"]["treelets"]["count"]


@pytest.mark.parametrize(
    ("setting", "field"),
    [
        ("treelets.prefetch_into=l3", "treelets.prefetch_into"),
        ("treelets.prefetch_lines=70000", "treelets.prefetch_lines"),
        ("treelets.prefetch=maybe", "treelets.prefetch"),
    ],
)
def test_bad_prefetch_fields_are_named(
    hairball_diffuse: Path, tmp_path: Path, setting: str, field: str
) -> None:
    result = simulate(sim_or_fail(), hairball_diffuse, tmp_path / "bad", *TREELETS, setting)
    assert result.returncode == 2
    assert field.split(".")[-1] in result.stderr, result.stderr


def test_prefetch_fields_are_sweep_axes() -> None:
    from rtsim.sweep.spec import load_spec

    spec_file = Path(__file__).resolve().parents[2] / "python/rtsim/specs/treelet_prefetch.yaml"
    spec = load_spec(spec_file)
    assert spec.grid["treelets.prefetch"] == [False, True]
    assert spec.grid["treelets.prefetch_into"] == ["l1", "l2"]
    assert len(list(spec.points())) == 8


@pytest.mark.parametrize("model", ["mimd", "simt"])
def test_prefetching_without_queues_changes_no_hit_or_work(
    hairball_diffuse: Path, tmp_path: Path, model: str
) -> None:
    """Chou et al.'s prefetcher on its own: the partition drives only the prefetcher, as rays
    step into treelets (no ray buffer, no queue); hits and the traversal are as without it."""
    base = (f"traversal.model={model}", "l2.size_kib=128")
    off = sim_stats(sim_or_fail(), hairball_diffuse, tmp_path / "off", *base)
    on = sim_stats(
        sim_or_fail(), hairball_diffuse, tmp_path / "on", *base, "treelets.prefetch=true"
    )
    assert on["validation"]["hit_mismatches"] == 0 and on["validation"]["work_mismatches"] == 0
    units, units_off = on["model"]["units"], off["model"]["units"]
    steps = [sum(u["steps"] for u in stats.values()) for stats in (units, units_off)]
    if model == "mimd":  # (a warp's steps depend on when its lanes refill: timing, not traversal)
        assert steps[0] == steps[1]
    assert on["summary"]["rays"] == off["summary"]["rays"]
    assert "ray_buffer" not in on["model"]
    table = on["model"]["treelet_prefetch"]
    assert 0 < table["prefetch"]["treelets_learnt"] <= table["treelets"]["count"]
    assert sum(u["prefetch"]["entries"] for u in units.values()) > 0
    assert sum(u["prefetch"]["sent"] for u in units.values()) > 0
    assert any(b["block"] == "treelet_prefetch" and b["instantiated"] for b in on["instantiated"])
