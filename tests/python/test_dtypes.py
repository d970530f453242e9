"""numpy reads every record with the layout C++ declares for it (traces/common/record_layout.h):
the sections' through rtsim._core.section_layouts(), each image region's from the trace's ACCL
descriptor. These pin the documented byte layouts (docs/trace_format.md, docs/bvh_layout.md,
docs/accel.md), so a layout change shows here as well as in the docs."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

import rtsim
from rtsim.trace_file import HIT_DTYPE, RAY_DTYPE, SECTION_DTYPES, WORK_DTYPE, dtype_of


def offsets(dtype: np.dtype) -> dict[str, int]:
    assert dtype.names is not None
    return {name: dtype.fields[name][1] for name in dtype.names}


def test_section_records_match_the_documented_layouts() -> None:
    assert RAY_DTYPE.itemsize == 40 and HIT_DTYPE.itemsize == 20
    assert offsets(RAY_DTYPE) == {
        "origin": 0, "tmin": 12, "direction": 16, "tmax": 28,
        "pixel": 32, "kind": 36, "flags": 37, "depth": 38,
    }  # fmt: skip
    assert RAY_DTYPE["origin"].shape == (3,)
    assert offsets(HIT_DTYPE) == {"prim": 0, "inst": 4, "t": 8, "u": 12, "v": 16}
    # WORK holds the traced work counters in declaration order, 4 bytes each; the model's own
    # (the mailbox's, a short stack's) come after them and are never in a trace.
    fields = rtsim._core.work_fields()
    names = [f["name"] for f in fields if f["traced"]]
    assert [f["name"] for f in fields if not f["traced"]] == [
        "mailbox_lookups", "mailbox_hits", "stack_drops", "restarts", "restart_steps",
        "restart_box_tests", "tlas_steps", "tlas_box_tests", "rp_box_hits", "rp_steps",
        "rp_box_tests", "rp_tri_tests", "obb_rotations",
    ]  # fmt: skip
    assert [f["name"] for f in fields][: len(names)] == names
    assert list(WORK_DTYPE.names or ()) == names
    assert WORK_DTYPE.itemsize == 4 * len(names)
    assert offsets(SECTION_DTYPES["frms"]) == {"first_ray": 0, "rays": 8}


def test_dtype_of_reads_a_scalar_record_and_pads_to_the_record_size() -> None:
    assert dtype_of([{"name": "", "type": "<u4", "offset": 0, "shape": []}]) == np.dtype("<u4")
    padded = dtype_of([{"name": "a", "type": "<f4", "offset": 4, "shape": [2]}], itemsize=16)
    assert padded.itemsize == 16 and padded.fields["a"][1] == 4 and padded["a"].shape == (2,)


CWNODE8_OFFSETS = {
    "p": 0, "e": 12, "imask": 15, "base_node": 16, "base_tri": 20, "meta": 24, "qlo": 32, "qhi": 56,
}  # fmt: skip
BVH2_NODE_OFFSETS = {"bounds": 0, "child_ref": 48, "child_count": 56}


@pytest.fixture(scope="module")
def traced(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str, str], rtsim.Trace]:
    """traced(scene, accel): a tiny trace of the scene with that structure, made once."""
    root = tmp_path_factory.mktemp("layouts")
    made: dict[tuple[str, str], rtsim.Trace] = {}

    def trace(scene: str, accel: str) -> rtsim.Trace:
        if (scene, accel) not in made:
            out = root / f"{scene}_{accel}"
            rtsim.trace_scene(scene, out, workload=["primary"], width=16, height=12, accel=accel)
            made[(scene, accel)] = rtsim.open_trace(out)
        return made[(scene, accel)]

    return trace


@pytest.mark.parametrize(
    ("accel", "node_offsets", "node_bytes"),
    [
        ("bvh2", BVH2_NODE_OFFSETS, 64),
        ("bvh4", {"bounds": 0, "child_ref": 96, "child_count": 112}, 128),
        ("bvh6", {"bounds": 0, "child_ref": 144, "child_count": 168}, 192),
        ("bvh8", {"bounds": 0, "child_ref": 192, "child_count": 224}, 256),
        ("cwbvh8", CWNODE8_OFFSETS, 80),
        ("cwbvh6", {"p": 0, "e": 12, "meta": 15, "bases": 21, "qlo": 28, "qhi": 46}, 64),
    ],
)
def test_node_regions_read_with_their_declared_layout(
    traced: Callable[[str, str], rtsim.Trace],
    accel: str,
    node_offsets: dict[str, int],
    node_bytes: int,
) -> None:
    trace = traced("cornell", accel)
    nodes = trace.nodes
    assert nodes is not None and nodes.dtype.itemsize == node_bytes
    assert offsets(nodes.dtype) == node_offsets
    tris = trace.triangles
    assert tris is not None
    assert offsets(tris.dtype) == {"v0": 0, "v1": 12, "v2": 24, "prim": 36, "inst": 40, "flags": 44}
    # Read with the right layout, the triangles' primitive ids are each scene triangle once.
    prims = np.sort(np.asarray(tris["prim"]))
    assert np.array_equal(prims, np.arange(len(tris)))


def test_grid_and_two_level_regions(traced: Callable[[str, str], rtsim.Trace]) -> None:
    grid = traced("cornell", "grid")
    cells, refs = grid.region("cells"), grid.region("prim_refs")
    assert offsets(cells.dtype) == {"first_ref": 0, "ref_count": 4}
    assert refs.dtype == np.dtype("<u4")
    assert int(np.asarray(cells["ref_count"]).sum()) == len(refs)
    grove = traced("grove", "bvh2")
    assert grove.accel["kind"] == "two_level"
    instances = grove.region("instances")
    assert instances.dtype.itemsize == 128
    assert offsets(instances.dtype)["object_to_world"] == 64
    assert offsets(grove.region("tlas_nodes").dtype) == BVH2_NODE_OFFSETS
    assert offsets(grove.region("blas_triangles").dtype)["prim"] == 36
