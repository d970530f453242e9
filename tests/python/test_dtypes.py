"""The numpy record dtypes mirror the packed C++ records of traces/format/trace_format.h."""

from __future__ import annotations

from rtsim.trace_file import (
    CWNODE6_DTYPE,
    CWNODE8_DTYPE,
    HIT_DTYPE,
    NODE_DTYPE,
    RAY_DTYPE,
    TRIANGLE_DTYPE,
    WORK_DTYPE,
    wide_node_dtype,
)


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


def test_wide_node_layouts() -> None:
    # docs/accel.md: WideNode<N> is 32 N bytes; CwNode8 80 and CwNode6 64, at these offsets.
    for width in (4, 6, 8):
        dtype = wide_node_dtype(width)
        assert dtype.itemsize == 32 * width
        assert dtype.fields["child_ref"][1] == 24 * width
        assert dtype.fields["child_count"][1] == 28 * width
    cw8 = {name: CWNODE8_DTYPE.fields[name][1] for name in CWNODE8_DTYPE.names}
    assert CWNODE8_DTYPE.itemsize == 80
    assert cw8 == {
        "p": 0,
        "e": 12,
        "imask": 15,
        "base_node": 16,
        "base_tri": 20,
        "meta": 24,
        "qlo": 32,
        "qhi": 56,
    }
    cw6 = {name: CWNODE6_DTYPE.fields[name][1] for name in CWNODE6_DTYPE.names}
    assert CWNODE6_DTYPE.itemsize == 64
    assert cw6 == {"p": 0, "e": 12, "meta": 15, "bases": 21, "qlo": 28, "qhi": 46}
