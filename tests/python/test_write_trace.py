"""Bring your own rays: rtsim.write_trace writes a trace exactly as the tracer does, the model
replays it, and trace_rays returns the same per-ray work as the trace records."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import rtsim
from rtsim.trace_file import RAY_KINDS
from trace_forge import read_sections


@pytest.fixture(scope="module")
def primary(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("write") / "primary"
    rtsim.trace_scene("cornell", out, workload="primary", width=40, height=30)
    return out


def test_same_rays_give_the_same_trace_file(primary: Path, tmp_path: Path) -> None:
    """The tracer's primary rays, given back as user rays: every section of trace.rtt is
    byte-identical but the rays' shading records and texel addresses, since rays given from
    Python carry no ray cone (width and spread 0: texels at the finest level, docs/shading.md)."""
    rays = rtsim.open_trace(primary).rays
    manifest = rtsim.write_trace(
        "cornell", rays["origin"], rays["direction"], rays["tmin"], rays["tmax"], out=tmp_path
    )
    traced, given = read_sections(primary / "trace.rtt"), read_sections(tmp_path / "trace.rtt")
    assert set(given) == set(traced)
    assert all(given[name] == traced[name] for name in given if name not in ("SHAD", "TXFT"))
    shade = rtsim.open_trace(tmp_path).section("SHAD")
    assert (shade["parent"] == -1).all() and (shade["cone_spread"] == 0).all()
    assert manifest["counts"]["rays"] == len(rays)
    assert manifest["workload"]["requested"] == "given"
    effects = {e["name"]: e for e in manifest["workload"]["effects"]}
    assert effects["primary"]["simulated"] and not effects["shadow"]["simulated"]
    assert manifest["accel"] == rtsim.open_trace(primary).manifest["accel"] | {
        "build_ms": manifest["accel"]["build_ms"]
    }


def test_mixed_kinds_replay_on_the_model(tmp_path: Path) -> None:
    scene = rtsim.load_scene("cornell")
    rng = np.random.default_rng(7)
    lo, hi = (np.float32(v) for v in scene.bounds)
    n = 300
    origins = (lo + (hi - lo) * rng.random((n, 3))).astype(np.float32)
    directions = rng.normal(size=(n, 3)).astype(np.float32)
    kinds = rng.choice(["diffuse", "shadow", "reflection"], size=n)
    tmax = np.where(kinds == "shadow", 1.0, np.inf).astype(np.float32)
    rtsim.write_trace(scene, origins, directions, 0.0, tmax, kind=kinds, out=tmp_path / "t")
    trace = rtsim.open_trace(tmp_path / "t")
    assert [RAY_KINDS[k] for k in trace.rays["kind"]] == list(kinds)
    assert np.array_equal(trace.rays["flags"] & 1, (kinds == "shadow").astype(np.uint8))
    assert np.array_equal(trace.rays["pixel"], np.arange(n))
    stats = rtsim.simulate(tmp_path / "t", fidelity="functional")
    assert stats.rays == n and stats.hit_mismatches == 0 and stats.work_mismatches == 0
    # The references are the tracer's hits: trace_rays agrees ray by ray.
    closest = rtsim.trace_rays(scene, origins, directions, 0.0, tmax)
    anyhit = rtsim.trace_rays(scene, origins, directions, 0.0, tmax, any_hit=True)
    expected = np.where(kinds == "shadow", anyhit["prim"], closest["prim"])
    assert np.array_equal(trace.hits["prim"], expected)


def test_trace_rays_returns_the_traces_work(primary: Path) -> None:
    trace = rtsim.open_trace(primary)
    r = trace.rays
    hits = rtsim.trace_rays(rtsim.load_scene("cornell"), r["origin"], r["direction"], r["tmin"],
                            r["tmax"])  # fmt: skip
    work = hits["work"]
    assert set(work.dtype.names) == set(trace.work.dtype.names)  # the C++ WorkCounts fields
    for name in work.dtype.names:
        assert np.array_equal(work[name], trace.work[name]), name
    assert work["steps"].sum() > 0 and np.array_equal(hits["prim"], trace.hits["prim"])


def test_bad_rays_raise_naming_the_argument(tmp_path: Path) -> None:
    one = np.float32([[0, 0, 0]])
    with pytest.raises(rtsim.RtsimError, match="laser"):
        rtsim.write_trace("cornell", one, one, kind="laser", out=tmp_path)
    with pytest.raises(rtsim.RtsimError, match="kind"):
        rtsim.write_trace("cornell", one, one, kind=["primary", "shadow"], out=tmp_path)
    with pytest.raises(ValueError, match="directions"):
        rtsim.write_trace("cornell", one, np.float32([[0, 0]]), out=tmp_path)
    with pytest.raises(rtsim.RtsimError, match="no rays"):
        rtsim.write_trace("cornell", np.zeros((0, 3), np.float32), np.zeros((0, 3)), out=tmp_path)
    assert not (tmp_path / "trace.rtt").exists()
