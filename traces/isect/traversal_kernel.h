#pragma once
// The traversal rules shared by the Traversal stepper (traversal.cpp) and trace_ray's fused
// loop (trace_ray.cpp): child selection at a node, the leaf's hit rules and the cull distance.
// Both call these same inline functions, so they visit the same nodes in the same order, count
// the same work and keep the same hits (docs/intersection.md; a test drives both on every ray).
#include <cmath>
#include <cstdint>

#include "traces/bvh/hw_layout.h"
#include "traces/common/ray.h"
#include "traces/isect/ray_box_kernel.h"
#include "traces/isect/ray_triangle_kernel.h"

namespace rtsim {

bool alpha_test_accepts(uint32_t prim, float u, float v, uint32_t coverage_x255);

namespace detail {

/// Throws rtsim::Error: a push onto a full traversal stack (kTraversalStackSize entries).
[[noreturn]] void throw_stack_overflow();

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

#if defined(__SSE2__)
/// Node step on SIMD lanes: both child boxes against [tmin, cull] (in every lane of tmin4 and
/// cull4), empty slots dropped. Returns the 2-bit mask of children hit; lanes 0 and 1 of
/// *tnear are their entry distances.
inline unsigned node_step_sse(const RayBoxPre& pre, const HwNode& node, __m128 tmin4,
                              __m128 cull4, __m128* tnear) {
    const unsigned mask = node_kernel_sse(pre, node, tmin4, cull4, tnear);
    // Empty slots never hit, whatever their box holds.
    const __m128i counts = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(node.child_count));
    const __m128i empty = _mm_cmpeq_epi32(counts, _mm_set1_epi32(int32_t(kEmptyChild)));
    return mask & ~unsigned(_mm_movemask_ps(_mm_castsi128_ps(empty))) & 3u;
}
#endif

/// Node step: both child boxes against [tmin, cull], empty slots dropped. Returns the 2-bit
/// mask of children hit and their entry distances.
inline unsigned node_step(const RayBoxPre& pre, const HwNode& node, float tmin, float cull,
                          float tnear[2]) {
#if defined(__SSE2__)
    __m128 tn;
    const unsigned mask = node_step_sse(pre, node, _mm_set1_ps(tmin), _mm_set1_ps(cull), &tn);
    _mm_storel_pi(reinterpret_cast<__m64*>(tnear), tn);
    return mask;
#else
    const unsigned mask = node_kernel(pre, node, tmin, cull, tnear);
    return mask & ~(unsigned(node.child_count[0] == kEmptyChild) |
                    (unsigned(node.child_count[1] == kEmptyChild) << 1));
#endif
}

/// The slot to visit next among the hit ones (mask != 0): the nearer, child 0 on equal entry
/// distances. When both hit, the other slot (returned ^ 1) is pushed.
inline unsigned next_slot(unsigned mask, const float tnear[2]) {
    if (mask == 3) return tnear[1] < tnear[0] ? 1u : 0u;
    return mask >> 1;
}

/// Leaf step: tests `count` triangles in storage order against the ray's own [tmin, tmax] (so
/// acceptance never depends on visit order), keeps the closest by (t, prim), runs the alpha
/// test of MASK triangles. `best.t` is the current best distance (ray.tmax before any hit) and
/// `cull_t` the cull distance derived from it. Returns true when an any-hit traversal is done.
template <bool kAnyHit>
inline bool leaf_step(const RayTrianglePre& pre, float tmin, float tmax,
                      const HwTriangle* triangles, uint32_t count, Hit& best,
                      float& cull_t, uint32_t& anyhit_calls) {
    for (uint32_t i = 0; i < count; ++i) {
        const HwTriangle& tri = triangles[i];
        TriangleHit th;
        if (!triangle_kernel(pre, tri.v0, tri.v1, tri.v2, tmin, tmax, &th)) continue;
        if (!kAnyHit && !closer(th.t, tri.prim, best.t, best.prim)) continue;
        // Alpha-MASK triangles: the any-hit (alpha) test decides.
        if (tri.flags & kTriAnyHit) {
            anyhit_calls += 1;
            const uint32_t coverage = (tri.flags >> kTriCoverageShift) & 0xFFu;
            if (!alpha_test_accepts(tri.prim, th.u, th.v, coverage)) continue;
        }
        best.prim = int32_t(tri.prim);
        best.inst = int32_t(tri.inst);
        best.t = th.t;
        best.u = th.u;
        best.v = th.v;
        cull_t = cull_distance(th.t);
        if (kAnyHit) return true;
    }
    return false;
}

}  // namespace detail
}  // namespace rtsim
