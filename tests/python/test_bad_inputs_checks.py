"""The bad-input suite, checks that must apply everywhere (docs/validation.md, "third round"):
sweep limits over every axis product, the spec check applying the simulator's own rules (one
resolution step, asked through `rtsim-sim --check-runs`), the Python API refusing what numpy
would convert with a loss, and the trace reader checking every field it trusts (reserved words,
kinds against their layouts, every reference), not only those a ray happens to reach.
"""

from __future__ import annotations

import json
import struct
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import rtsim
from conftest import rtsim_trace
from rtsim.cli import main
from rtsim.launcher import SimJob, find_sim, run_sim
from rtsim.sweep.spec import SpecError, parse_spec
from trace_forge import read_sections, write_trace

SPEC = "scenes: [cornell]\nworkloads: [{rays: [primary], resolution: 8x8}]\n"


def _err(capsys: pytest.CaptureFixture[str]) -> str:
    return " ".join(capsys.readouterr().err.split())


# ---------------------------------------------------------------------------------------------
# Sweep limits: an accel build-settings product of 216,000 structures ran 400 s, printing nothing.


def test_accel_settings_product_held_to_the_run_limit(tmp_path: Path, capsys) -> None:
    spec = tmp_path / "big.yaml"
    spec.write_text(
        SPEC + "accel:\n  - kind: bvh2\n    build:\n      bins: ["
        + ", ".join(map(str, range(2, 62)))
        + "]\n      max_leaf_size: [" + ", ".join(map(str, range(1, 61)))
        + "]\n      traversal_cost: [" + ", ".join(map(str, range(1, 61))) + "]\n"
    )  # fmt: skip
    t0 = time.monotonic()
    code = main(["sweep", str(spec), "-o", str(tmp_path / "out"), "--no-progress"])
    err = _err(capsys)
    assert code == 2, err
    assert "accel[0].build" in err and "216,000 structures" in err, err
    assert "60 bins x 60 max_leaf_size x 60 traversal_cost" in err, err
    assert not (tmp_path / "out").exists()
    assert time.monotonic() - t0 < 10


def test_accel_entries_together_held_to_the_run_limit() -> None:
    leaves, bins = ", ".join(map(str, range(1, 61))), ", ".join(map(str, range(2, 62)))
    entry = (
        f"  - {{kind: bvh2, label: L{{}}, build: {{max_leaf_size: [{leaves}], bins: [{bins}]}}}}\n"
    )
    text = SPEC + "accel:\n" + "".join(entry.replace("{}", str(i)) for i in range(30))
    with pytest.raises(SpecError, match=r"accel\[27\].build.*room for 2,800 more"):
        parse_spec(text, source="s.yaml")


# ---------------------------------------------------------------------------------------------
# The spec check applies the simulator's rules: each of these passed the check, traced every
# scene, then failed in every run.

REFUSED_AT_THE_CHECK = {
    "restart_trail_on_a_grid": (
        "accel: [grid]\ngrid:\n  traversal.stack_overflow: [restart_trail]\n",
        "traversal.stack_overflow",
    ),
    "rp_boxes_on_an_octree": (
        "accel: [octree]\ngrid:\n  traversal.box_precision_bits: [8]\n",
        "traversal.box_precision_bits",
    ),
    "lanes_not_dividing_contexts": (
        "config:\n  set: {traversal.model: simt, traversal.ray_contexts: 16}\n"
        "grid:\n  traversal.simt.lanes: [5]\n",
        "traversal.simt.lanes",
    ),
    "mailbox_out_of_range": (
        "accel: [grid]\ngrid:\n  mailbox.entries: [1000000]\n",
        "mailbox.entries",
    ),
    "l1_size_not_a_cache": ("grid:\n  l1.size_kib: [16, 3]\n", "l1.size_kib"),
    "units_past_the_memory_estimate": (
        "grid:\n  traversal.units: [100000000]\n",
        "traversal.units",
    ),
}


@pytest.mark.parametrize("case", sorted(REFUSED_AT_THE_CHECK))
def test_spec_refused_where_the_simulator_would_refuse(case: str, tmp_path: Path, capsys) -> None:
    extra, key = REFUSED_AT_THE_CHECK[case]
    spec = tmp_path / "s.yaml"
    spec.write_text(SPEC + extra)
    code = main(["sweep", str(spec), "-o", str(tmp_path / "out"), "--no-progress"])
    err = _err(capsys)
    assert code == 2, err
    assert str(spec) in err and key in err and "would be refused by the simulator" in err, err
    assert not (tmp_path / "out" / "traces").exists()  # nothing traced


# Property: a spec is refused at the check exactly when one of its runs, simulated on a real
# trace of its structure, would be refused (exit 2); an accepted spec's runs all simulate.

POOL = {
    "traversal.model": ["mimd", "simt", "packet"],
    "traversal.stack_overflow": ["spill", "restart_trail"],
    "traversal.box_precision_bits": [0, 7],
    "mailbox.entries": [0, 4, 65],
    "traversal.simt.lanes": [4, 5, 8],
    "traversal.ray_contexts": [0, 16],
    "fidelity": ["functional", "analytic"],
    "l1.size_kib": [16, 3],
}
ACCELS = ["bvh2", "kdtree", "grid", "octree"]


@pytest.fixture(scope="module")
def small_traces(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    out = {}
    for accel in ACCELS:
        folder = tmp_path_factory.mktemp(f"trace-{accel}")
        rtsim_trace("cornell", "-o", str(folder), "--resolution", "4x4", "--workload", "primary",
                    "--accel", accel)  # fmt: skip
        out[accel] = folder
    return out


@settings(
    max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    accel=st.sampled_from(ACCELS),
    grid=st.dictionaries(
        st.sampled_from(sorted(POOL)), st.just(None), min_size=1, max_size=3
    ).flatmap(
        lambda keys: st.fixed_dictionaries(
            {
                k: st.lists(st.sampled_from(POOL[k]), min_size=1, max_size=2, unique=True)
                for k in keys
            }
        )
    ),
)
def test_spec_check_agrees_with_the_simulator(
    accel: str, grid: dict, small_traces: dict[str, Path], tmp_path_factory: pytest.TempPathFactory
) -> None:
    text = (
        SPEC
        + f"accel: [{accel}]\n"
        + "grid:\n"
        + "".join(f"  {k}: {json.dumps(v)}\n" for k, v in grid.items())
    )
    try:
        spec = parse_spec(text, source="prop.yaml")
        refused = None
    except SpecError as err:
        spec, refused = None, str(err)
    if spec is not None:
        for run in spec.runs():
            folder = tmp_path_factory.mktemp("run")
            (folder / "config.json").write_text(run.config.to_json())
            job = SimJob(
                trace=small_traces[accel], out_dir=folder / "r", config=folder / "config.json"
            )
            result = run_sim(job, timeout=120)
            assert result.returncode == 0, (run.params, result.stderr[-1500:])
    else:
        # Some run of the grid is refused by the simulator itself.
        import itertools

        exits = []
        for values in itertools.product(*grid.values()):
            sets = [f"{k}={v}" for k, v in zip(grid, values, strict=True)]
            folder = tmp_path_factory.mktemp("run")
            result = run_sim(
                SimJob(trace=small_traces[accel], out_dir=folder, sets=sets), timeout=120
            )
            exits.append(result.returncode)
        assert 2 in exits, (refused, exits)


# ---------------------------------------------------------------------------------------------
# trace_rays converted complex (a ComplexWarning) and bool arrays silently.


@pytest.mark.parametrize(
    ("argument", "value", "fragment"),
    [
        ("origins", np.zeros((2, 3), complex) + 1j, "complex"),
        ("directions", np.ones((2, 3), bool), "bools"),
        ("tmin", np.zeros(2, bool), "bools"),
        ("tmax", np.full(2, 5 + 0j), "complex"),
        ("origins", np.array([["1", "2", "3"], ["1", "2", "3"]]), "values"),
    ],
    ids=["complex_origins", "bool_directions", "bool_tmin", "complex_tmax", "text_origins"],
)
def test_trace_rays_refuses_complex_and_bool_arrays(argument: str, value, fragment: str) -> None:
    scene = rtsim.load_scene("cornell")
    args = {"origins": np.zeros((2, 3)), "directions": np.float32([[0, 0, -1]] * 2),
            "tmin": 0.0, "tmax": np.inf}  # fmt: skip
    args[argument] = value
    with pytest.raises(rtsim.RtsimError, match=fragment) as info:
        rtsim.trace_rays(scene, **args)
    assert argument in str(info.value)


# ---------------------------------------------------------------------------------------------
# The trace reader checks every field it trusts (was: caught only if a ray reached it).


def _trace(tmp_path: Path, accel: str, *extra: str) -> Path:
    folder = tmp_path / f"good-{accel}"
    rtsim_trace("cornell", "-o", str(folder), "--resolution", "8x8", "--workload", "primary",
                "--accel", accel, *extra)  # fmt: skip
    return folder / "trace.rtt"


def _region(sections, name: str) -> str:
    accel = json.loads(bytes(sections["accel"]))
    index = [r["name"] for r in accel["regions"]].index(name)
    return f"RG{index:02d}"


def _first_leaf(payload: bytearray, record: int, is_leaf) -> int:
    for at in range(0, len(payload), record):
        if is_leaf(payload[at : at + record]):
            return at
    raise AssertionError("no leaf")


def edit_octree_leaf(s) -> None:
    nodes = s[_region(s, "nodes")]
    at = _first_leaf(nodes, 16, lambda r: r[0] == 0)
    struct.pack_into("<I", nodes, at + 12, 7)  # word3: reserved in a leaf


def edit_octree_leaf_index_bits(s) -> None:
    nodes = s[_region(s, "nodes")]
    at = _first_leaf(nodes, 16, lambda r: r[0] == 0)
    struct.pack_into("<I", nodes, at, 5 << 8)  # word0's index bits: reserved in a leaf


def edit_bih_leaf(s) -> None:
    nodes = s[_region(s, "nodes")]
    at = _first_leaf(nodes, 12, lambda r: r[0] & 3 == 3)
    struct.pack_into("<I", nodes, at + 8, 1)  # word2: reserved in a leaf


def relabel_octant(s) -> None:
    accel = json.loads(bytes(s["accel"]))
    accel["kind"] = "cwbvh8_octant"  # the image stays distance-ordered
    s["accel"] = bytearray(json.dumps(accel).encode())


def move_prim_base(s) -> None:
    blocks = s[_region(s, "leaf_blocks")]
    words = struct.unpack_from("<B", blocks, 3)[0]
    at = 4 * words  # the second block, so a ray through the first never meets it
    struct.pack_into("<I", blocks, at + 4, 0x7FFF0000)


TRACE_EDITS = {
    "octree_leaf_word3": ("octree", (), edit_octree_leaf, "reserved"),
    "octree_leaf_index_bits": ("octree", (), edit_octree_leaf_index_bits, "reserved"),
    "bih_leaf_word2": ("bih", (), edit_bih_leaf, "reserved word"),
    "cwbvh8_relabelled_octant": ("cwbvh8", (), relabel_octant, "params.order"),
    "prim_base_out_of_range": (
        "bvh2",
        ("--build-set", "compressed_leaves=true"),
        move_prim_base,
        "primitive id",
    ),
}


@pytest.mark.parametrize("case", sorted(TRACE_EDITS))
def test_edited_trace_refused_on_open(case: str, tmp_path: Path) -> None:
    accel, extra, edit, fragment = TRACE_EDITS[case]
    good = _trace(tmp_path, accel, *extra)
    sections = read_sections(good)
    edit(sections)
    bad = write_trace(tmp_path / "bad" / "trace.rtt", sections)
    sim = subprocess.run(
        [str(find_sim()), str(bad), "-o", str(tmp_path / "run")],
        capture_output=True, text=True, timeout=120, check=False,
    )  # fmt: skip
    assert sim.returncode == 2, sim.stderr
    assert str(bad) in sim.stderr and fragment in sim.stderr, sim.stderr
