"""Any-hit child orders (docs/accel.md, "Any-hit child order") at the functional and timed
levels, on a binary and an 8-wide BVH: every reordered shadow ray keeps its occlusion, and the run
reports its own work per ray beside the trace's nearest-first work, which equals the trace's own
work records of those rays; the timed levels walk exactly as the functional level does."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import rtsim
from conftest import checked, run_rtsim
from rtsim.errors import ArgumentValueError
from rtsim.kinds import RAY_KINDS


@pytest.fixture(scope="module", params=["bvh2", "bvh8"])
def trace(tmp_path_factory: pytest.TempPathFactory, request: pytest.FixtureRequest) -> Path:
    out = tmp_path_factory.mktemp("anyhit") / f"cornell-{request.param}"
    made = run_rtsim("trace", "cornell", "-o", str(out), "--resolution", "24x18",
                     "--workload", "primary,shadow", "--accel", request.param)  # fmt: skip
    assert made.returncode == 0, made.stderr
    return out


@pytest.mark.parametrize("order", ["largest_box", "fixed"])
def test_reordered_rays_report_their_work(trace: Path, sim_exe: Path, tmp_path: Path,
                                          order: str) -> None:  # fmt: skip
    own = {}
    for fidelity in ("functional", "approx", "detailed", "analytic"):
        # The analytic level steps every ray with its functional caches (its statistical ones
        # take unstepped rays' work from the trace: refused, the capability table's rule).
        caches = ["analytic.caches=functional"] if fidelity == "analytic" else []
        stats = checked(sim_exe, trace, tmp_path / fidelity, f"fidelity={fidelity}", *caches,
                        f"traversal.anyhit_order={order}")  # fmt: skip
        v = stats["validation"]
        assert v["hit_mismatches"] == v["work_mismatches"] == 0, fidelity
        r = v["reordered_anyhit"]
        t = rtsim.open_trace(trace)
        shadow = t.rays["kind"] == RAY_KINDS.index("shadow")
        assert r["rays"] == int(shadow.sum()) == stats["workload"]["occlusion_rays"]
        for key in ("steps", "box_tests", "tri_tests"):
            assert r["trace_order"][key] == pytest.approx(float(np.mean(t.work[key][shadow])))
            assert r["own"][key] > 0
        own[fidelity] = r["own"]
        if fidelity != "functional":
            assert stats["summary"]["cycles"] > 0
    assert own["approx"] == own["detailed"] == own["analytic"] == own["functional"]


def test_nearest_reorders_nothing(trace: Path, sim_exe: Path, tmp_path: Path) -> None:
    stats = checked(sim_exe, trace, tmp_path / "run", "fidelity=functional")
    assert "reordered_anyhit" not in stats["validation"]


def test_packet_units_walk_shadow_packets_in_the_order(trace: Path, sim_exe: Path,
                                                       tmp_path: Path) -> None:  # fmt: skip
    """Packet units take the order at node steps of shadow packets (the boxes' order is every
    ray's), so a shadow ray does about its single-ray reordered work (exactly, in a packet of
    shadow rays alone), checked in full against the reference packet loop at every level."""
    alone = checked(sim_exe, trace, tmp_path / "mimd", "fidelity=functional",
                    "traversal.anyhit_order=largest_box")  # fmt: skip
    own = {}
    for fidelity in ("functional", "approx", "detailed"):
        stats = checked(sim_exe, trace, tmp_path / fidelity, f"fidelity={fidelity}",
                        "traversal.model=packet", "traversal.anyhit_order=largest_box")  # fmt: skip
        v = stats["validation"]
        assert v["hit_mismatches"] == v["work_mismatches"] == 0, fidelity
        assert v["reordered_anyhit"]["rays"] == alone["validation"]["reordered_anyhit"]["rays"]
        own[fidelity] = v["reordered_anyhit"]["own"]
    assert own["approx"] == own["detailed"] == own["functional"]
    for key, value in alone["validation"]["reordered_anyhit"]["own"].items():
        assert own["functional"][key] == pytest.approx(value, rel=0.02), key


def test_a_trace_in_the_runs_order_checks_its_work_exactly(
    trace: Path, sim_exe: Path, tmp_path: Path
) -> None:
    """`rtsim trace --anyhit-order` writes the any-hit rays' reference work in that order: a run
    in the same order checks every ray's work (no reordered rays), its reordered work is the
    nearest-first trace's `own` work, and the analytic level's statistical caches take it; a run
    in another order than the trace's is reordered against it (and refused there)."""
    kind = trace.name.split("-")[1]
    ordered = tmp_path / "ordered"
    made = run_rtsim("trace", "cornell", "-o", str(ordered), "--resolution", "24x18",
                     "--workload", "primary,shadow", "--accel", kind,
                     "--anyhit-order", "largest_box")  # fmt: skip
    assert made.returncode == 0, made.stderr
    assert rtsim.open_trace(ordered).manifest["workload"]["anyhit_order"] == "largest_box"
    near = checked(sim_exe, trace, tmp_path / "near", "fidelity=functional",
                   "traversal.anyhit_order=largest_box")  # fmt: skip
    same = checked(sim_exe, ordered, tmp_path / "same", "fidelity=functional",
                   "traversal.anyhit_order=largest_box")  # fmt: skip
    assert "reordered_anyhit" not in same["validation"]
    t = rtsim.open_trace(ordered)
    shadow = t.rays["kind"] == RAY_KINDS.index("shadow")
    for key in ("steps", "box_tests", "tri_tests"):
        own = near["validation"]["reordered_anyhit"]["own"][key]
        assert float(np.mean(t.work[key][shadow])) == pytest.approx(own), key
    analytic = checked(sim_exe, ordered, tmp_path / "analytic", "fidelity=analytic",
                       "traversal.anyhit_order=largest_box")  # fmt: skip
    assert analytic["summary"]["cycles"] > 0
    other = checked(sim_exe, ordered, tmp_path / "other", "fidelity=functional")
    assert other["validation"]["reordered_anyhit"]["rays"] == int(shadow.sum())
    refused = run_rtsim("simulate", str(ordered), "-o", str(tmp_path / "refused"),
                        "--set", "fidelity=analytic")  # fmt: skip
    assert refused.returncode != 0 and "anyhit_order" in refused.stderr


def test_an_order_the_structure_lacks_is_refused_by_name(tmp_path: Path) -> None:
    bad = run_rtsim("trace", "cornell", "-o", str(tmp_path / "grid"), "--resolution", "8x6",
                    "--accel", "grid", "--anyhit-order", "fixed")  # fmt: skip
    assert bad.returncode != 0 and "grid" in bad.stderr and "any-hit child order" in bad.stderr
    with pytest.raises(ArgumentValueError, match="anyhit_order"):
        rtsim.trace_scene("cornell", tmp_path / "x", anyhit_order="sideways")
