#pragma once
// The ray/box arithmetic itself, inline so the traversal's hot loop can inline it; ray_box.cpp
// exposes the same code as the public functions of ray_box.h (one arithmetic, docs/architecture.md, rule 1).
//
// Robust slab test of Ize 2013, "Robust BVH Ray Traversal" (JCGT 2(2)):
//   near/far slab distances (plane - origin) * inv_dir, the plane picked by the sign bit of
//   inv_dir; the far distance moved away from zero by 2*gamma(3) (pbrt 3rd ed. 3.9:
//   gamma(n) = n*eps / (1 - n*eps), eps = 2^-24) so no box the ray truly crosses is missed to
//   rounding. tnear = max(tmin, near_x, near_y, near_z); hit iff tnear <= min(tmax, far').
// NaN convention: a slab distance is NaN only for 0 * inf, i.e. a ray parallel to an axis whose
// origin lies exactly in that slab plane. Such a distance is ignored (the fold keeps the running
// value), so a ray lying in a slab plane counts as inside that slab.
// The SSE2 node test computes exactly the scalar box test lane by lane (IEEE single-precision
// add/mul; MAXPS/MINPS return their second operand on NaN, which is the fold above). It reads
// the HwNode::bounds layout, one axis of both children per 16 bytes, and takes the near and far
// plane of each axis at byte offsets fixed per ray, so no per-node select is needed.
#include <cmath>
#include <limits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "traces/bvh/hw_layout.h"
#include "traces/isect/ray_box.h"

namespace rtsim {
namespace detail {

constexpr double kGamma3 = 3.0 * 0x1p-24 / (1.0 - 3.0 * 0x1p-24);
/// Far-distance scale for far >= 0 and far < 0 (moves it away from zero).
constexpr float kFarUp = float(1.0 + 2.0 * kGamma3);
constexpr float kFarDown = float(1.0 - 2.0 * kGamma3);

/// One box, scalar. Writes the entry distance, returns hit.
inline bool box_kernel(const RayBoxPre& pre, const float lo[3], const float hi[3], float tmin,
                       float tmax, float* tnear) {
    float tn = tmin;
    float tf = std::numeric_limits<float>::infinity();
    for (int a = 0; a < 3; ++a) {
        const bool neg = std::signbit(pre.inv_dir4[a]);
        const float n = ((neg ? hi[a] : lo[a]) - pre.origin4[a]) * pre.inv_dir4[a];
        const float f = ((neg ? lo[a] : hi[a]) - pre.origin4[a]) * pre.inv_dir4[a];
        // NaN-ignoring max/min: a NaN slab distance compares false and leaves tn/tf unchanged.
        tn = n > tn ? n : tn;
        tf = f < tf ? f : tf;
    }
    tf *= tf >= 0.0f ? kFarUp : kFarDown;
    tf = tf < tmax ? tf : tmax;
    *tnear = tn;
    return tn <= tf;
}

#if defined(__SSE2__)
/// Bitwise select of the far-distance scale: kFarDown + (far >= 0 ? kFarStep : 0) is exactly
/// kFarUp or kFarDown (both are 1 -+ 3 * 2^-23; their difference and the sum are exact).
constexpr float kFarStep = kFarUp - kFarDown;
static_assert(kFarDown + kFarStep == kFarUp, "far scale select must be exact");

/// Lanes of constants, loaded as one memory operand each.
alignas(16) constexpr float kInf4[4] = {std::numeric_limits<float>::infinity(),
                                        std::numeric_limits<float>::infinity(),
                                        std::numeric_limits<float>::infinity(),
                                        std::numeric_limits<float>::infinity()};
alignas(16) constexpr float kFarDown4[4] = {kFarDown, kFarDown, kFarDown, kFarDown};
alignas(16) constexpr float kFarStep4[4] = {kFarStep, kFarStep, kFarStep, kFarStep};

/// Both children of a node at once, in the HwNode::bounds layout: the ray's near and far planes
/// are picked per axis by the byte offsets of RayBoxPre (no per-node select), lanes 0 and 1 hold
/// child 0 and child 1. Lane for lane the same operations, in the same order, as box_kernel.
/// tmin4 and tmax4 hold the interval in every lane. Returns the movemask of the hit lanes
/// (bits 0 and 1; lanes 2 and 3 undefined) and the entry distances in lanes 0 and 1 of *tnear.
inline unsigned node_kernel_sse(const RayBoxPre& pre, const HwNode& node, __m128 tmin4,
                                __m128 tmax4, __m128* tnear) {
    const char* b = reinterpret_cast<const char*>(node.bounds);
    const auto pair = [b](uint32_t offset) {  // two floats: the plane of both children
        return _mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(b + offset)));
    };
    const auto high = [b](__m128 lo, uint32_t offset) {
        return _mm_loadh_pi(lo, reinterpret_cast<const __m64*>(b + offset));
    };
    // (near x, near y) and (far x, far y) of both children; z: (near z, far z).
    const __m128 n_xy = high(pair(pre.near_offset[0]), pre.near_offset[1]);
    const __m128 f_xy = high(pair(pre.far_offset[0]), pre.far_offset[1]);
    const __m128 nf_z = high(pair(pre.near_offset[2]), pre.far_offset[2]);
    const __m128 org_xy = _mm_load_ps(pre.origin_xy), inv_xy = _mm_load_ps(pre.inv_dir_xy);
    const __m128 org_z = _mm_load_ps(pre.origin_z), inv_z = _mm_load_ps(pre.inv_dir_z);
    const __m128 tn_xy = _mm_mul_ps(_mm_sub_ps(n_xy, org_xy), inv_xy);
    const __m128 tf_xy = _mm_mul_ps(_mm_sub_ps(f_xy, org_xy), inv_xy);
    const __m128 t_z = _mm_mul_ps(_mm_sub_ps(nf_z, org_z), inv_z);
    // NaN-ignoring folds, slab value first (MAXPS/MINPS return the second operand on NaN):
    // the same order as the scalar loop, x then y then z.
    __m128 tn = _mm_max_ps(tn_xy, tmin4);
    tn = _mm_max_ps(_mm_movehl_ps(tn_xy, tn_xy), tn);
    tn = _mm_max_ps(t_z, tn);
    __m128 tf = _mm_min_ps(tf_xy, _mm_load_ps(kInf4));
    tf = _mm_min_ps(_mm_movehl_ps(tf_xy, tf_xy), tf);
    tf = _mm_min_ps(_mm_movehl_ps(t_z, t_z), tf);
    const __m128 pos = _mm_cmpge_ps(tf, _mm_setzero_ps());
    const __m128 scale = _mm_add_ps(_mm_load_ps(kFarDown4), _mm_and_ps(pos, _mm_load_ps(kFarStep4)));
    tf = _mm_min_ps(_mm_mul_ps(tf, scale), tmax4);
    *tnear = tn;
    return unsigned(_mm_movemask_ps(_mm_cmple_ps(tn, tf)));
}

inline unsigned node_kernel(const RayBoxPre& pre, const HwNode& node, float tmin, float tmax,
                            float tnear[2]) {
    __m128 tn;
    const unsigned mask = node_kernel_sse(pre, node, _mm_set1_ps(tmin), _mm_set1_ps(tmax), &tn);
    _mm_storel_pi(reinterpret_cast<__m64*>(tnear), tn);
    return mask & 3u;
}
#else
inline unsigned node_kernel(const RayBoxPre& pre, const HwNode& node, float tmin, float tmax,
                            float tnear[2]) {
    unsigned mask = 0;
    for (int c = 0; c < 2; ++c) {
        const float lo[3] = {node.lo(c, 0), node.lo(c, 1), node.lo(c, 2)};
        const float hi[3] = {node.hi(c, 0), node.hi(c, 1), node.hi(c, 2)};
        mask |= unsigned(box_kernel(pre, lo, hi, tmin, tmax, &tnear[c])) << c;
    }
    return mask;
}
#endif

}  // namespace detail
}  // namespace rtsim
