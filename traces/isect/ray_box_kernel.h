#pragma once
// The ray/box arithmetic itself, inline so the traversal's hot loop can inline it; ray_box.cpp
// exposes the same code as the public functions of ray_box.h (one arithmetic, DESIGN rule 1).
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
// add/mul; MAXPS/MINPS return their second operand on NaN, which is the fold above).
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
/// Both children of a node at once: lanes hold x, y, z of one child, then a 2x3 transpose.
inline unsigned node_kernel(const RayBoxPre& pre, const HwNode& node, float tmin, float tmax,
                            float tnear[2]) {
    const __m128 org = _mm_load_ps(pre.origin4);
    const __m128 inv = _mm_load_ps(pre.inv_dir4);
    const __m128 neg = _mm_castsi128_ps(_mm_srai_epi32(_mm_castps_si128(inv), 31));
    // Slab distances of both planes; lane 3 holds a neighbouring box coordinate and is never
    // used. (hi[1] is loaded from hi[0][2] and rotated: the word after it is child_ref[0], an
    // integer that reads as a denormal float, and denormal operands cost a microcode assist.)
    const __m128 hi1_raw = _mm_loadu_ps(&node.hi[0][2]);
    const __m128 lo0 = _mm_mul_ps(_mm_sub_ps(_mm_loadu_ps(node.lo[0]), org), inv);
    const __m128 lo1 = _mm_mul_ps(_mm_sub_ps(_mm_loadu_ps(node.lo[1]), org), inv);
    const __m128 hi0 = _mm_mul_ps(_mm_sub_ps(_mm_loadu_ps(node.hi[0]), org), inv);
    const __m128 hi1 = _mm_mul_ps(
        _mm_sub_ps(_mm_shuffle_ps(hi1_raw, hi1_raw, _MM_SHUFFLE(0, 3, 2, 1)), org), inv);
    // Near plane = hi where inv_dir is negative, else lo; far the other one.
    const __m128 n0 = _mm_or_ps(_mm_and_ps(neg, hi0), _mm_andnot_ps(neg, lo0));
    const __m128 n1 = _mm_or_ps(_mm_and_ps(neg, hi1), _mm_andnot_ps(neg, lo1));
    const __m128 f0 = _mm_or_ps(_mm_and_ps(neg, lo0), _mm_andnot_ps(neg, hi0));
    const __m128 f1 = _mm_or_ps(_mm_and_ps(neg, lo1), _mm_andnot_ps(neg, hi1));
    // Transpose to (child 0, child 1) pairs per axis: xy = (x0, x1, y0, y1), z = (z0, z1, ..).
    const __m128 nxy = _mm_unpacklo_ps(n0, n1), nz = _mm_unpackhi_ps(n0, n1);
    const __m128 fxy = _mm_unpacklo_ps(f0, f1), fz = _mm_unpackhi_ps(f0, f1);
    // NaN-ignoring folds, slab value first: the same order as the scalar loop.
    __m128 tn = _mm_max_ps(nxy, _mm_set1_ps(tmin));
    tn = _mm_max_ps(_mm_movehl_ps(nxy, nxy), tn);
    tn = _mm_max_ps(nz, tn);
    __m128 tf = _mm_min_ps(fxy, _mm_set1_ps(std::numeric_limits<float>::infinity()));
    tf = _mm_min_ps(_mm_movehl_ps(fxy, fxy), tf);
    tf = _mm_min_ps(fz, tf);
    const __m128 pos = _mm_cmpge_ps(tf, _mm_setzero_ps());
    const __m128 scale = _mm_or_ps(_mm_and_ps(pos, _mm_set1_ps(kFarUp)),
                                   _mm_andnot_ps(pos, _mm_set1_ps(kFarDown)));
    tf = _mm_min_ps(_mm_mul_ps(tf, scale), _mm_set1_ps(tmax));
    const unsigned mask = unsigned(_mm_movemask_ps(_mm_cmple_ps(tn, tf))) & 3u;
    _mm_storel_pi(reinterpret_cast<__m64*>(tnear), tn);
    return mask;
}
#else
inline unsigned node_kernel(const RayBoxPre& pre, const HwNode& node, float tmin, float tmax,
                            float tnear[2]) {
    const bool h0 = box_kernel(pre, node.lo[0], node.hi[0], tmin, tmax, &tnear[0]);
    const bool h1 = box_kernel(pre, node.lo[1], node.hi[1], tmin, tmax, &tnear[1]);
    return unsigned(h0) | (unsigned(h1) << 1);
}
#endif

}  // namespace detail
}  // namespace rtsim
