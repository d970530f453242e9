"""The numpy record dtypes mirror the packed C++ records of traces/format/trace_format.h."""

from __future__ import annotations

from rtsim.trace_file import HIT_DTYPE, NODE_DTYPE, RAY_DTYPE, TRIANGLE_DTYPE, WORK_DTYPE


def test_record_sizes() -> None:
    assert RAY_DTYPE.itemsize == 40
    assert HIT_DTYPE.itemsize == 20
    assert WORK_DTYPE.itemsize == 32
    assert NODE_DTYPE.itemsize == 64
    assert TRIANGLE_DTYPE.itemsize == 48


def test_ray_record_offsets() -> None:
    offsets = {name: RAY_DTYPE.fields[name][1] for name in RAY_DTYPE.names}
    assert offsets == {
        "origin": 0,
        "tmin": 12,
        "direction": 16,
        "tmax": 28,
        "pixel": 32,
        "kind": 36,
        "flags": 37,
        "depth": 38,
    }


def test_hw_node_offsets() -> None:
    offsets = {name: NODE_DTYPE.fields[name][1] for name in NODE_DTYPE.names}
    assert offsets == {"bounds": 0, "child_ref": 48, "child_count": 56}
    tri = {name: TRIANGLE_DTYPE.fields[name][1] for name in TRIANGLE_DTYPE.names}
    assert tri == {"v0": 0, "v1": 12, "v2": 24, "prim": 36, "inst": 40, "flags": 44}
