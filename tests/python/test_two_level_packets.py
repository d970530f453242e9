"""Packets through two levels (traces/accel/two_level/two_level_packet.h): the grove's instances
traced two-level over binary, wide and compressed BLASes replay on packet units at every level
with 0 hit and 0 work mismatches (each ray's hit is the single-ray reference's); a primary-ray
packet shares its TLAS steps; the hybrid splits inside instances (its lanes mode listed as
unused: split rays walk serially); an animated two-level scene (the skinned tube, refitted per
frame) replays on packets too."""

from __future__ import annotations

from pathlib import Path

import pytest

import rtsim
from conftest import checked, rtsim_trace

PACKETS = ("traversal.model=packet", "traversal.packet.lanes=16")


@pytest.fixture(scope="module")
def grove(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("grove_packets")
    out = {}
    for kind in ("bvh2", "bvh8", "cwbvh8"):
        folder = root / kind
        rtsim_trace(
            "grove", "-o", str(folder), "--accel", kind, "--resolution", "24x18",
            "--workload", "primary,shadow,diffuse",
        )  # fmt: skip
        assert rtsim.open_trace(folder).manifest["accel"]["kind"] == "two_level"
        out[kind] = folder / "trace.rtt"
    return out


@pytest.mark.parametrize("level", ["functional", "analytic", "approx", "detailed"])
def test_two_level_packets_match_the_reference(
    sim_exe: Path, grove: dict[str, Path], tmp_path: Path, level: str
) -> None:
    for kind, trace in grove.items():
        stats = checked(sim_exe, trace, tmp_path / kind, *PACKETS, f"fidelity={level}")
        if level in ("approx", "detailed"):
            units = stats["model"]["units"].values()
            assert sum(u["packet_steps"] for u in units) > 0, kind
            assert 0 < stats["summary"]["simd_efficiency"] <= 1


@pytest.mark.parametrize("kind", ["bvh2", "cwbvh8"])
def test_two_level_packets_split_inside_instances_and_take_stack_prefetch(
    sim_exe: Path, grove: dict[str, Path], tmp_path: Path, kind: str
) -> None:
    whole = checked(sim_exe, grove[kind], tmp_path / "whole", *PACKETS, "fidelity=detailed")
    stats = checked(
        sim_exe, grove[kind], tmp_path / "split", *PACKETS, "traversal.packet.split_below=0.5",
        "traversal.packet.split_walks=lanes", "traversal.stack_prefetch=2", "fidelity=detailed",
    )  # fmt: skip
    unused = {u["key"]: u["why"] for u in stats["summary"]["resolved"]["unused"]}
    assert "traversal.packet.split_below" not in unused
    assert "serial" in unused["traversal.packet.split_walks"]
    assert "traversal.stack_prefetch" not in unused
    units = stats["model"]["units"].values()
    assert sum(u["packet_splits"] for u in units) > 0
    assert sum(u["packet_split_steps"] for u in units) > 0
    assert sum(u["packet_splits"] for u in whole["model"]["units"].values()) == 0


def test_packets_on_a_moving_two_level_scene(sim_exe: Path, tmp_path: Path) -> None:
    trace = tmp_path / "tube"
    rtsim_trace(
        "skinned_tube", "-o", str(trace), "--frames", "3", "--frame-policy", "refit",
        "--resolution", "16x12",
    )  # fmt: skip
    stats = checked(sim_exe, trace / "trace.rtt", tmp_path / "run", *PACKETS)
    assert stats["summary"]["frames"] == 3
