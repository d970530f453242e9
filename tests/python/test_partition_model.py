"""The space-partitioning structures end to end (docs/accel.md): `rtsim trace --accel kdtree`,
`bih` and `octree` trace small scenes and the model replays each at every fidelity level with
zero hit and zero work mismatches, issuing plane tests on the `plane` pipeline and taking the
structure's stack entry size; mailboxes change no hit and save triangle tests; builder settings
round-trip through the manifest and are refused by name."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import rtsim
from conftest import checked, rtsim_trace, run_rtsim, trace_per_structure

STRUCTURES = {
    "kdtree": ["--accel", "kdtree"],
    "bih": ["--accel", "bih"],
    "octree": ["--accel", "octree"],
    "grid": ["--accel", "grid"],
    "bvh2": ["--accel", "bvh2"],
}
LEVELS = ("functional", "analytic", "approx", "detailed")
ENTRY_BYTES = {"kdtree": 12, "bih": 12, "octree": 32, "grid": 8, "bvh2": 8}


@pytest.fixture(scope="module")
def traces(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """rotated_walls at 24x18 (primary, shadow, diffuse), once per structure."""
    root = tmp_path_factory.mktemp("partition_traces")
    return trace_per_structure(root, "rotated_walls", "24x18", "primary,shadow,diffuse", STRUCTURES)


@pytest.mark.parametrize("level", LEVELS)
@pytest.mark.parametrize("structure", ["kdtree", "bih", "octree"])
def test_model_replays_every_structure_at_every_level(
    traces: dict[str, Path], sim_exe: Path, tmp_path: Path, structure: str, level: str
) -> None:
    stats = checked(sim_exe, traces[structure], tmp_path / "run", f"fidelity={level}")
    resolved = json.loads((tmp_path / "run" / "config.resolved.json").read_text())
    assert resolved["traversal"]["stack_entry_bytes"] == ENTRY_BYTES[structure]
    if level == "functional":
        return
    blocks = {b["block"]: b["instantiated"] for b in stats["instantiated"]}
    assert blocks["plane"] is True and blocks["box"] is True and blocks["triangle"] is True
    if level != "analytic":  # the analytic level reports pipeline loads, not blocks' counts
        tests = sum(p["tests"] for p in stats["model"]["plane"].values())
        assert tests == int(rtsim.open_trace(traces[structure]).work["plane_tests"].sum()) > 0


def test_structures_trace_the_binary_bvhs_hits(traces: dict[str, Path]) -> None:
    binary = rtsim.open_trace(traces["bvh2"])
    for name in ("kdtree", "bih", "octree"):
        ours = rtsim.open_trace(traces[name])
        assert np.array_equal(ours.rays, binary.rays)
        closest = (np.asarray(ours.rays["flags"]) & 1) == 0
        assert np.array_equal(
            ours.hits[closest].view(np.uint32), binary.hits[closest].view(np.uint32)
        )
        manifest = json.loads((traces[name] / "manifest.json").read_text())["accel"]
        assert manifest["stack_entry_bytes"] == ENTRY_BYTES[name]
        assert ours.nodes is not None and ours.nodes.dtype.itemsize == manifest["node_bytes"]


def test_stack_entry_bytes_override_and_spill_traffic(
    traces: dict[str, Path], sim_exe: Path, tmp_path: Path
) -> None:
    # One on-chip entry: the kd-tree spills; 12-byte entries move 1.5x the bytes of 8-byte ones.
    own = checked(sim_exe, traces["kdtree"], tmp_path / "own", "traversal.stack_entries=1")
    forced = checked(sim_exe, traces["kdtree"], tmp_path / "forced", "traversal.stack_entries=1",
                      "traversal.stack_entry_bytes=8")  # fmt: skip

    def spills(stats: dict[str, Any]) -> tuple[int, int]:
        writes = sum(u["stack_spill_writes"] for u in stats["model"]["units"].values())
        return writes, sum(
            c["by_kind"]["stack"]["write_bytes"] for c in stats["model"]["l1"].values()
        )

    (own_writes, own_bytes), (forced_writes, forced_bytes) = spills(own), spills(forced)
    assert own_writes == forced_writes > 0  # the same traversal spills the same entries
    assert own_bytes == 12 * own_writes and forced_bytes == 8 * forced_writes


@pytest.mark.parametrize("structure", ["grid", "kdtree", "octree"])
def test_mailbox_changes_no_hit_and_saves_tests(
    traces: dict[str, Path], sim_exe: Path, tmp_path: Path, structure: str
) -> None:
    base = checked(sim_exe, traces[structure], tmp_path / "base")
    assert base["summary"]["mailbox_hits_per_ray"] is None and "mailbox" not in base
    for level in ("functional", "approx"):
        stats = checked(
            sim_exe, traces[structure], tmp_path / level, "mailbox.entries=8", f"fidelity={level}"
        )
        m = stats["mailbox"]
        work = rtsim.open_trace(traces[structure]).work
        assert m["tri_tests_without_mailbox"] == int(work["tri_tests"].sum())
        assert m["tri_tests"] + m["hits"] == m["tri_tests_without_mailbox"] and m["hits"] > 0
        assert m["sram_bytes"] == 8 * 16 * 8 * 4 and stats["area"]["mm2"]["mailbox"] > 0
        if level == "approx":
            tests = sum(p["tests"] for p in stats["model"]["triangle"].values())
            assert tests == m["tri_tests"]  # the pipelines ran only the tests not skipped
            assert stats["energy"]["per_ray_nj"]["mailbox"] > 0


def test_the_statistical_analytic_level_scales_the_mailbox_from_its_sample(
    traces: dict[str, Path], sim_exe: Path, tmp_path: Path
) -> None:
    """Its stepped sample's mailbox hits, scaled to the trace, take tests off its triangle work."""
    runs = {}
    for name, sets in (("plain", []), ("mailbox", ["--set", "mailbox.entries=4"])):
        result = run_rtsim(
            "simulate", str(traces["kdtree"]), "-o", str(tmp_path / name), "--no-progress",
            "--set", "fidelity=analytic", *sets,
        )  # fmt: skip
        assert result.returncode == 0, result.stderr
        runs[name] = json.loads((tmp_path / name / "stats.json").read_text())
    for s in runs.values():
        assert s["summary"]["hit_mismatches"] == 0 and s["summary"]["work_mismatches"] == 0
    assert runs["mailbox"]["summary"]["cycles"] <= runs["plain"]["summary"]["cycles"]


def test_builder_settings_round_trip_through_the_manifest(tmp_path: Path) -> None:
    folder = tmp_path / "kd"
    rtsim_trace(
        "cornell", "-o", str(folder), "--resolution", "16x12", "--workload", "primary",
        "--accel", "kdtree", "--build-set", "empty_bonus=0.5", "--build-set", "clip=false",
    )  # fmt: skip
    accel = json.loads((folder / "manifest.json").read_text())["accel"]
    assert accel["build_set"] == {"empty_bonus": 0.5, "clip": False}
    settings = accel["build_settings"]
    assert (
        settings["empty_bonus"] == 0.5
        and settings["clip"] is False
        and settings["traversal_cost"] == 15
    )
    # The manifest's settings rebuild the same structure.
    again = tmp_path / "again"
    rtsim.trace_scene("cornell", again, workload="primary", width=16, height=12, accel="kdtree",
                      builder="", build_settings=settings)  # fmt: skip
    assert np.array_equal(rtsim.open_trace(again).nodes, rtsim.open_trace(folder).nodes)
    bad = run_rtsim(
        "trace", "cornell", "-o", str(tmp_path / "bad"), "--accel", "grid", "--build-set", "bins=8"
    )
    assert bad.returncode == 2 and "unknown setting 'bins' (it takes: density" in bad.stderr
    schema = {k["name"]: k for k in rtsim._core.accel_kinds()}
    assert schema["bvh2"]["settings"]["lbvh"]["morton_bits"]["default"] == 10
