"""Reduced-precision box tests end to end (docs/accel.md, "Reduced-precision box tests"): on a
binary and a compressed wide BVH, at every level that takes them, the narrower box test changes
no hit and no reference work count (the hit checker compares them with the trace), its extra walk
is reported in the `box_precision` section and costs node steps the units see, grows as the
mantissa narrows, and the box pipeline's energy and area shrink with it; the knob is a config
field with its range and a sweep axis, refused by name where it cannot run."""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest

import rtsim
from conftest import checked, run_rtsim, simulate
from rtsim.sweep.spec import parse_spec


@pytest.mark.parametrize("level", ["functional", "approx", "detailed"])
@pytest.mark.parametrize("accel", ["bvh2", "cwbvh8"])
def test_narrow_boxes_keep_hits_and_reference_work(
    small_hairball_traces: dict[str, Path], sim_exe: Path, tmp_path: Path, accel: str, level: str
) -> None:
    narrow = checked(
        sim_exe,
        small_hairball_traces[accel],
        tmp_path / "n",
        "traversal.box_precision_bits=4",
        f"fidelity={level}",
    )
    fp32 = checked(sim_exe, small_hairball_traces[accel], tmp_path / "f", f"fidelity={level}")
    assert "box_precision" not in fp32
    bp = narrow["box_precision"]
    assert bp["bits"] == 4
    assert bp["box_hits"] > 0 and bp["steps"] > 0 and bp["tri_tests"] > 0
    assert 0 < bp["extra_steps_fraction"] < 5
    # Reference work unchanged: the summary's work is the fp32 walk's.
    assert narrow["summary"]["rays"] == fp32["summary"]["rays"]
    # Cheaper, smaller box tests; every box test (the extra ones too) priced at the narrow width.
    assert bp["box_test_pj"] < bp["box_test_pj_fp32"] and bp["box_mm2"] < bp["box_mm2_fp32"]
    assert narrow["area"]["mm2"]["box"] == pytest.approx(bp["box_mm2"])
    assert narrow["energy"]["op_pj"]["box"] == pytest.approx(bp["box_test_pj"])
    assert fp32["energy"]["op_pj"]["box"] == pytest.approx(bp["box_test_pj_fp32"])
    if level != "functional":
        # The units scheduled the extra node steps on top of the fp32 walk's.
        steps = sum(u["steps"] for u in narrow["model"]["units"].values())
        fp32_steps = sum(u["steps"] for u in fp32["model"]["units"].values())
        assert steps > fp32_steps


def test_extra_work_grows_as_bits_shrink(
    small_hairball_traces: dict[str, Path], sim_exe: Path, tmp_path: Path
) -> None:
    seen = []
    for bits in (20, 12, 8, 4):
        stats = checked(
            sim_exe, small_hairball_traces["cwbvh8"], tmp_path / str(bits),
            f"traversal.box_precision_bits={bits}", "fidelity=functional",
        )  # fmt: skip
        bp = stats["box_precision"]
        seen.append((bp["steps"], bp["tri_tests"], bp["box_hits"], -bp["box_test_pj"]))
    for finer, coarser in itertools.pairwise(seen):
        assert all(c >= f for f, c in zip(finer, coarser, strict=True)), seen
    assert seen[-1][0] > seen[0][0]


def test_box_precision_is_refused_by_name_where_it_cannot_run(
    small_hairball_traces: dict[str, Path], sim_exe: Path, tmp_path: Path
) -> None:
    knob = "traversal.box_precision_bits"
    r = simulate(sim_exe, small_hairball_traces["kdtree"], tmp_path / "k", f"{knob}=8")
    assert r.returncode == 2 and knob in r.stderr and "kdtree" in r.stderr
    # the statistical analytic level scales the extra walk it measures on its stepped sample
    checked(
        sim_exe, small_hairball_traces["bvh2"], tmp_path / "a", f"{knob}=8", "fidelity=analytic"
    )
    for bad in ("23", "-1", "eight"):
        r = simulate(sim_exe, small_hairball_traces["bvh2"], tmp_path / f"b{bad}", f"{knob}={bad}")
        assert r.returncode == 2 and "box_precision_bits" in r.stderr, (bad, r.stderr)
    r = simulate(
        sim_exe,
        small_hairball_traces["bvh2"],
        tmp_path / "p",
        f"{knob}=8",
        "traversal.model=packet",
    )
    assert r.returncode == 2 and knob in r.stderr and "packet" in r.stderr
    # analytic with functional caches steps every ray and takes it
    stats = checked(
        sim_exe, small_hairball_traces["bvh2"], tmp_path / "af", f"{knob}=6", "fidelity=analytic",
        "analytic.caches=functional",
    )  # fmt: skip
    assert stats["box_precision"]["steps"] > 0


def test_the_knob_is_a_config_field_and_a_sweep_axis() -> None:
    info = rtsim.config.field_info("traversal.box_precision_bits")
    assert (info.metadata["min"], info.metadata["max"]) == (0, 22)
    assert rtsim.config.SimConfig().traversal.box_precision_bits == 0
    spec = parse_spec(
        "scenes: [cornell]\nworkloads: [{rays: [primary]}]\naccel: [cwbvh8]\ngrid:\n"
        "  traversal.box_precision_bits: [0, 8, 12]\n",
        "s.yaml",
    )
    assert {r.config.traversal.box_precision_bits for r in spec.runs()} == {0, 8, 12}
    # out-of-range values are refused by rtsim-sim naming the field (test above)


def test_the_summary_prints_the_extra_walk_and_the_narrow_pipeline(
    small_hairball_traces: dict[str, Path], tmp_path: Path
) -> None:
    result = run_rtsim(
        "simulate", str(small_hairball_traces["bvh2"]), "-o", str(tmp_path / "run"),
        "--no-progress", "--set", "traversal.box_precision_bits=8", "--set", "fidelity=functional",
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    out = " ".join(result.stdout.split())
    assert "reduced-precision box tests (8 mantissa bits)" in out
    assert "extra node steps" in out and "box pipelines mm^2 (fp32)" in out
