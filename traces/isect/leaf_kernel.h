#pragma once
// The hit rules every acceleration structure shares (docs/intersection.md): how a triangle test
// becomes the best hit (closest by (t, prim), alpha-MASK triangles decided by the any-hit test),
// and the cull distance derived from the best hit. Every stepper and every fused reference loop
// calls these same inline functions, so all structures keep the same hits bit for bit.
#include <cmath>
#include <cstdint>

#include "traces/common/hw_triangle.h"
#include "traces/common/ray.h"
#include "traces/isect/ray_capsule_kernel.h"
#include "traces/isect/ray_sphere_kernel.h"
#include "traces/isect/ray_triangle_kernel.h"

namespace rtsim {

/// Deterministic stochastic alpha test of a MASK triangle: accepts a fraction `coverage` of the
/// surface, decided by a hash of (prim, quantised u, v). Same answer in the tracer and the model.
bool alpha_test_accepts(uint32_t prim, float u, float v, uint32_t coverage_x255);

namespace detail {

/// Closest-hit order on (t, prim): nearer first, ties to the smaller primitive id. A best prim
/// of -1 (no hit yet) compares as the largest unsigned id, so a hit at exactly tmax is accepted.
inline bool closer(float t, uint32_t prim, float best_t, int32_t best_prim) {
    return t < best_t || (t == best_t && prim < uint32_t(best_prim));
}

/// Culling distance for a best hit at t: t widened by a relative 2^-10. The watertight t has an
/// error of a few ulps of the triangle's largest ray-space depth, while a box's entry distance
/// is good to gamma(3); a hit that ties with (or beats) the best may lie on its box's boundary,
/// e.g. at a shared vertex. Culling at t itself could then drop it, and the result would depend
/// on the visit order. The margin covers depth/t ratios up to about 1000 and costs a visit only
/// for boxes entered within 0.1% behind the best hit.
inline float cull_distance(float t) { return t + std::fabs(t) * 0x1p-10f; }

/// The primitive test of one record: a sphere's (kPrimSphere), a capsule's (kPrimCapsule) or a
/// triangle's.
inline bool primitive_kernel(const RayTrianglePre& pre, const HwTriangle& rec, float tmin, float tmax,
                             TriangleHit* hit) {
    if (__builtin_expect(is_curved(rec), 0)) {
        if (is_sphere(rec)) return sphere_kernel(pre, rec.v0, rec.v1[0], tmin, tmax, hit);
        return capsule_kernel(pre, rec.v0, rec.v1, rec.v2[0], rec.v2[1], tmin, tmax, hit);
    }
    return triangle_kernel(pre, rec.v0, rec.v1, rec.v2, tmin, tmax, hit);
}

/// True when some of `count` records is curved (a structure's view notes it once, at load).
inline bool any_curved(const HwTriangle* records, uint64_t count) {
    for (uint64_t i = 0; i < count; ++i)
        if (is_curved(records[i])) return true;
    return false;
}

/// A leaf's tests by pipeline: spheres and capsules (counted only when the structure has curved
/// records) and triangles.
struct LeafTests {
    uint32_t triangles = 0, spheres = 0, capsules = 0;
};
inline LeafTests leaf_tests(const HwTriangle* records, uint32_t count, bool has_curved) {
    LeafTests t;
    if (has_curved)
        for (uint32_t i = 0; i < count; ++i) t.spheres += is_sphere(records[i]), t.capsules += is_capsule(records[i]);
    t.triangles = count - t.spheres - t.capsules;
    return t;
}
/// Adds a leaf's tests to the ray's work.
inline void count_leaf_tests(WorkCounts& w, const LeafTests& t) {
    w.tri_tests += t.triangles;
    w.sphere_tests += t.spheres;
    w.capsule_tests += t.capsules;
}

/// Tests one triangle (or sphere) against the ray's own [tmin, tmax] (so acceptance never depends on visit
/// order) and makes it the best hit if it is closer (closest hit) and passes the alpha test of
/// a MASK triangle. Returns true when the triangle became the best hit.
template <bool kAnyHit>
inline bool triangle_step(const RayTrianglePre& pre, float tmin, float tmax, const HwTriangle& tri,
                          Hit& best, float& cull_t, uint32_t& anyhit_calls) {
    TriangleHit th;
    if (!primitive_kernel(pre, tri, tmin, tmax, &th)) return false;
    if (!kAnyHit && !closer(th.t, tri.prim, best.t, best.prim)) return false;
    // Alpha-MASK triangles: the any-hit (alpha) test decides.
    if (tri.flags & kTriAnyHit) {
        const uint32_t coverage = (tri.flags >> kTriCoverageShift) & 0xFFu;
        anyhit_calls += 1;
        if (!alpha_test_accepts(tri.prim, th.u, th.v, coverage)) {
            // A curved primitive's far side shows where its near side is cut out: its next
            // crossing (beyond the first) gets an alpha test of its own.
            if (!is_curved(tri) || !primitive_kernel(pre, tri, th.t, tmax, &th)) return false;
            if (!kAnyHit && !closer(th.t, tri.prim, best.t, best.prim)) return false;
            anyhit_calls += 1;
            if (!alpha_test_accepts(tri.prim, th.u, th.v, coverage)) return false;
        }
    }
    best.prim = int32_t(tri.prim);
    best.inst = int32_t(tri.inst);
    best.t = th.t;
    best.u = th.u;
    best.v = th.v;
    cull_t = cull_distance(th.t);
    return true;
}

/// Leaf step: tests `count` triangles in storage order (triangle_step each). `best.t` is the
/// current best distance (ray.tmax before any hit) and `cull_t` the cull distance derived from
/// it. Returns true when an any-hit traversal is done.
template <bool kAnyHit>
inline bool leaf_step(const RayTrianglePre& pre, float tmin, float tmax,
                      const HwTriangle* triangles, uint32_t count, Hit& best,
                      float& cull_t, uint32_t& anyhit_calls) {
    for (uint32_t i = 0; i < count; ++i)
        if (triangle_step<kAnyHit>(pre, tmin, tmax, triangles[i], best, cull_t, anyhit_calls) && kAnyHit)
            return true;
    return false;
}

}  // namespace detail
}  // namespace rtsim
