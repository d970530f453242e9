"""The other structures end to end (docs/accel.md): `rtsim trace --accel grid` and
`--accel bvh2 --builder sbvh` trace small scenes, the manifest records the structure, and the model
replays each trace at every fidelity level with zero hit and zero work mismatches (the grid also
with treelets, i.e. its brick partition, and on an alpha-MASK scene, i.e. the any-hit stage).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import rtsim
from conftest import checked, rtsim_trace, run_rtsim, trace_per_structure

STRUCTURES = {
    "grid": ["--accel", "grid"],
    "sbvh": ["--accel", "bvh2", "--builder", "sbvh"],
}
LEVELS = ("functional", "analytic", "approx", "detailed")


@pytest.fixture(scope="module")
def traces(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """cornell at 32x24 (primary, shadow, diffuse), once per structure."""
    root = tmp_path_factory.mktemp("accel_traces")
    return trace_per_structure(root, "cornell", "32x24", "primary,shadow,diffuse", STRUCTURES)


@pytest.mark.parametrize("level", LEVELS)
@pytest.mark.parametrize("structure", list(STRUCTURES))
def test_model_replays_every_structure(
    traces: dict[str, Path], sim_exe: Path, tmp_path: Path, structure: str, level: str
) -> None:
    stats = checked(sim_exe, traces[structure], tmp_path / "run", f"fidelity={level}")
    if level == "functional":
        assert stats["summary"]["cycles"] is None
        return
    blocks = {b["block"]: b["instantiated"] for b in stats["instantiated"]}
    # The grid issues cell steps (the pipeline configured as `cell`); a BVH does not.
    assert blocks.get("cell") is (structure == "grid")
    assert blocks.get("box") is True and blocks.get("triangle") is True
    assert stats["summary"]["cycles"] > 0


def test_grid_bricks_and_any_hit(
    traces: dict[str, Path], sim_exe: Path, tmp_path: Path, scenes_dir: Path
) -> None:
    # Treelet scheduling over the grid's bricks; 1 KiB bricks make rays move at most cells.
    stats = checked(
        sim_exe, traces["grid"], tmp_path / "bricks",
        "treelets.enabled=true", "treelets.treelet_kib=1",
    )  # fmt: skip
    units = stats["model"]["units"].values()
    assert sum(u["rays_parked"] for u in units) > 0, "rays should move between bricks"
    # Alpha-MASK triangles through the grid: the any-hit stage runs and matches.
    folder = tmp_path / "alpha"
    scene = scenes_dir / "AlphaBlendModeTest" / "AlphaBlendModeTest.gltf"
    rtsim_trace(
        str(scene), "-o", str(folder), "--resolution", "32x24",
        "--workload", "primary,shadow", "--accel", "grid",
    )  # fmt: skip
    stats = checked(sim_exe, folder, tmp_path / "alpha_run")
    assert {b["block"]: b["instantiated"] for b in stats["instantiated"]}["anyhit"] is True


def test_manifest_records_the_structure(traces: dict[str, Path]) -> None:
    grid = json.loads((traces["grid"] / "manifest.json").read_text())["accel"]
    assert grid["kind"] == "grid" and grid["builder"] == "uniform"
    assert [r["name"] for r in grid["regions"]] == ["cells", "prim_refs", "triangles"]
    assert grid["cells"] == grid["resolution"][0] * grid["resolution"][1] * grid["resolution"][2]
    trace = rtsim.open_trace(traces["grid"])
    cells = trace.region("cells")
    assert int(cells["ref_count"].sum()) == grid["references"] == len(trace.region("prim_refs"))
    work = trace.work
    assert (work["cell_steps"] == work["steps"]).all() and work["refs"].sum() > 0
    sbvh = json.loads((traces["sbvh"] / "manifest.json").read_text())["accel"]
    assert sbvh["kind"] == "bvh2" and sbvh["builder"] == "sbvh"
    triangles = json.loads((traces["sbvh"] / "manifest.json").read_text())["scene"]["triangles"]
    assert (
        sbvh["sbvh"]["references"] == len(rtsim.open_trace(traces["sbvh"]).triangles) >= triangles
    )


def test_cli_lists_structures_and_refuses_a_wrong_builder(tmp_path: Path) -> None:
    result = run_rtsim("trace", "--help")
    assert result.returncode == 0
    assert "grid" in result.stdout and "sbvh" in result.stdout
    result = run_rtsim(
        "trace", "cornell", "-o", str(tmp_path / "x"), "--accel", "grid", "--builder", "sbvh"
    )
    assert result.returncode != 0
    assert "no builder 'sbvh'" in result.stderr
