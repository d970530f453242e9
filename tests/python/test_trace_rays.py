"""trace_rays against a numpy brute-force tracer, argument checking and invalid rays."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import rtsim

EDGE = 1e-4  # barycentric margin: rays this close to an edge may go either way


def brute_force(tris: np.ndarray, origins: np.ndarray, dirs: np.ndarray, chunk: int = 64):
    """Möller–Trumbore in float64 over all triangles: (t, prim, ambiguous) per ray."""
    parts = [
        _brute_force(tris, origins[i : i + chunk], dirs[i : i + chunk])
        for i in range(0, len(origins), chunk)
    ]
    return tuple(np.concatenate(p) for p in zip(*parts, strict=True))


def _brute_force(tris: np.ndarray, origins: np.ndarray, dirs: np.ndarray):
    v0, v1, v2 = (tris[:, i].astype(np.float64) for i in range(3))
    e1, e2 = v1 - v0, v2 - v0
    o = origins.astype(np.float64)[:, None, :]
    d = dirs.astype(np.float64)[:, None, :]
    p = np.cross(d, e2[None])
    det = np.einsum("rtk,tk->rt", p, e1)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        s = o - v0[None]
        u = np.einsum("rtk,rtk->rt", s, p) * inv
        q = np.cross(s, e1[None])
        v = np.einsum("rtk,rtk->rt", d, q) * inv
        t = np.einsum("rtk,tk->rt", q, e2) * inv
    w = 1.0 - u - v
    inside = (u >= 0) & (v >= 0) & (w >= 0) & (t > 0) & (np.abs(det) > 1e-12)
    near_edge = (np.minimum(np.minimum(u, v), w) > -EDGE) & (np.minimum(np.minimum(u, v), w) < EDGE)
    t_hit = np.where(inside, t, np.inf)
    prim = np.argmin(t_hit, axis=1)
    best = t_hit[np.arange(len(prim)), prim]
    prim = np.where(np.isfinite(best), prim, -1)
    # Ambiguous: a near-edge crossing in front of the ray, or two hits within a hair in t.
    ambiguous = (near_edge & (t > 0)).any(axis=1)
    sorted_t = np.sort(t_hit, axis=1)
    if sorted_t.shape[1] > 1:
        with np.errstate(invalid="ignore"):
            close = np.isfinite(sorted_t[:, 1]) & (
                sorted_t[:, 1] - sorted_t[:, 0] < 1e-4 * sorted_t[:, 1]
            )
        ambiguous |= close
    return best, prim, ambiguous


def random_rays(scene: rtsim.Scene, n: int, seed: int):
    rng = np.random.default_rng(seed)
    lo, hi = (np.array(b) for b in scene.bounds)
    centre, extent = (lo + hi) / 2, (hi - lo)
    origins = centre + (rng.random((n, 3)) - 0.5) * 1.6 * extent
    dirs = rng.normal(size=(n, 3))
    return origins.astype(np.float32), dirs.astype(np.float32)


def test_matches_brute_force(cornell: rtsim.Scene) -> None:
    origins, dirs = random_rays(cornell, 1000, seed=7)
    hits = rtsim.trace_rays(cornell, origins, dirs, 0.0, math.inf)
    t_ref, prim_ref, ambiguous = brute_force(cornell.triangles(), origins, dirs)
    clear = ~ambiguous
    assert clear.mean() > 0.9
    assert hits["valid"].all()
    assert ((hits["prim"] >= 0) == (prim_ref >= 0))[clear].all()
    assert (hits["prim"] == prim_ref)[clear].all()
    hit = clear & (prim_ref >= 0)
    assert 0.1 < hit.mean() < 0.99  # the sample exercises both hits and misses
    np.testing.assert_allclose(hits["t"][hit], t_ref[hit], rtol=1e-4)


def test_result_fields(cornell: rtsim.Scene) -> None:
    origins, dirs = random_rays(cornell, 50, seed=1)
    hits = rtsim.trace_rays(cornell, origins, dirs)
    assert {"prim", "inst", "t", "u", "v", "valid"} <= set(hits.dtype.names)
    assert hits["prim"].dtype == np.int32 and hits["t"].dtype == np.float32
    miss = hits["prim"] < 0
    assert np.isinf(hits["t"][miss]).all()
    assert (hits["inst"][~miss] >= 0).all()


def test_any_hit_agrees_on_occlusion(cornell: rtsim.Scene) -> None:
    origins, dirs = random_rays(cornell, 500, seed=3)
    closest = rtsim.trace_rays(cornell, origins, dirs)
    occluded = rtsim.trace_rays(cornell, origins, dirs, any_hit=True)
    assert ((closest["prim"] >= 0) == (occluded["prim"] >= 0)).all()


def test_per_ray_limits(cornell: rtsim.Scene) -> None:
    origins, dirs = random_rays(cornell, 300, seed=5)
    full = rtsim.trace_rays(cornell, origins, dirs)
    hit = full["prim"] >= 0
    # Cutting each ray just before its closest hit leaves nothing to hit.
    tmax = np.where(hit, full["t"] * np.float32(0.999), np.inf).astype(np.float32)
    cut = rtsim.trace_rays(cornell, origins, dirs, 0.0, tmax)
    assert (cut["prim"][hit] == -1).all()
    # A window around the hit keeps it.
    around = rtsim.trace_rays(cornell, origins, dirs, full["t"] * 0.5, full["t"] * 2.0)
    assert (around["prim"][hit] == full["prim"][hit]).all()


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3),
    st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3).filter(
        lambda d: sum(x * x for x in d) > 1e-6
    ),
)
@example(origin=[-1.401298464324817e-45, 0.0, 0.0], direction=[1.0, 0.0, 0.0])  # subnormal t
def test_closest_hit_is_first_along_the_ray(
    cornell: rtsim.Scene, origin: list[float], direction: list[float]
) -> None:
    scene = cornell
    o = np.array([origin], dtype=np.float32)
    d = np.array([direction], dtype=np.float32)
    hit = rtsim.trace_rays(scene, o, d)[0]
    if hit["prim"] < 0 or hit["t"] <= 0.0:  # a miss, or a hit at the origin itself
        return
    assert 0.0 <= hit["u"] <= 1.0 and 0.0 <= hit["v"] <= 1.0 and hit["u"] + hit["v"] <= 1.0001
    # Strictly before the hit: 0.999 t, or the float below t where 0.999 t rounds back to t (a
    # subnormal t, e.g. an origin 1e-45 in front of a wall: hypothesis found it).
    t = np.float32(hit["t"])
    limit = min(t * np.float32(0.999), np.nextafter(t, np.float32(0.0)))
    before = rtsim.trace_rays(scene, o, d, 0.0, limit)[0]
    assert before["prim"] == -1


def test_invalid_rays_miss(cornell: rtsim.Scene) -> None:
    origins = np.zeros((4, 3), dtype=np.float32)
    dirs = np.tile(np.float32([0.0, 0.0, 1.0]), (4, 1))
    origins[0, 1] = np.nan  # NaN origin
    dirs[1] = 0.0  # zero direction
    dirs[2, 0] = np.inf  # infinite direction
    hits = rtsim.trace_rays(
        cornell, origins, dirs, np.float32([0, 0, 0, 5]), np.float32([1, 1, 1, 1])
    )
    assert (hits["valid"] == [False, False, False, False]).all()  # the last has tmin > tmax
    assert (hits["prim"] == -1).all()


def test_shape_errors(cornell: rtsim.Scene) -> None:
    good = np.zeros((5, 3), dtype=np.float32)
    with pytest.raises(ValueError, match="origins"):
        rtsim.trace_rays(cornell, np.zeros((5, 2)), good)
    with pytest.raises(ValueError, match="directions"):
        rtsim.trace_rays(cornell, good, np.zeros(15))
    with pytest.raises(ValueError, match="directions"):
        rtsim.trace_rays(cornell, good, np.zeros((4, 3)))
    with pytest.raises(ValueError, match="tmax"):
        rtsim.trace_rays(cornell, good, good, 0.0, np.ones(4))
    with pytest.raises(ValueError, match="tmin"):
        rtsim.trace_rays(cornell, good, good, np.ones((5, 1)), 1.0)


def test_empty_and_float64_input(cornell: rtsim.Scene) -> None:
    assert len(rtsim.trace_rays(cornell, np.zeros((0, 3)), np.zeros((0, 3)))) == 0
    origins, dirs = random_rays(cornell, 20, seed=9)
    as32 = rtsim.trace_rays(cornell, origins, dirs)
    as64 = rtsim.trace_rays(cornell, origins.astype(np.float64), dirs.astype(np.float64))
    assert (as32 == as64).all()
