// The fused reference loop of the fp32 wide BVHs (wide_accel.h): WideStepper<Fp32Codec<N>>'s
// node and leaf steps in one loop, per-ray state in registers, local counters, and the node's
// child boxes tested four at a time with SSE. Lane for lane the box test is detail::box_kernel
// (traces/isect/ray_box_kernel.h): the same IEEE operations in the same order (MAXPS/MINPS
// return their second operand on NaN, which is the kernel's NaN-ignoring fold), so the children
// hit, their entry distances, the visit order, the hits and every work count equal the
// stepper's; test_wide checks that ray by ray. Without SSE2 the stepper's loop is used.
#include <cmath>
#include <cstring>

#include "traces/accel/wide/wide_accel.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace rtsim {
namespace {

#if defined(__SSE2__)
/// Lanes 4g .. 4g+3 of a row of N values (N = 6, g = 1: two values, lanes 2 and 3 zero).
template <int N>
inline __m128 load_group(const float* row, int g) {
    if (N - 4 * g >= 4) return _mm_loadu_ps(row + 4 * g);
    return _mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(row + 4 * g)));
}

template <int N>
inline uint32_t valid_slots(const WideNode<N>& node) {
    const __m128i empty = _mm_set1_epi32(int32_t(kEmptyChild));
    uint32_t valid = 0;
    for (int g = 0; g * 4 < N; ++g) {
        const __m128i c = _mm_castps_si128(load_group<N>(reinterpret_cast<const float*>(node.child_count), g));
        valid |= uint32_t(~_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(c, empty))) & 0xF) << (4 * g);
    }
    return valid & ((1u << N) - 1);
}

/// The ray's constants for the node test.
struct Lanes {
    __m128 org[3], inv[3], tmin, inf, down, step;
    uint32_t near_row[3], far_row[3];  ///< float offsets of each axis's near and far plane rows
};

/// Every child box of a node against [tmin, cull]: the hit mask; entry distances in tnear.
template <int N>
inline uint32_t node_test(const Lanes& l, const WideNode<N>& node, __m128 cull4, float* tnear) {
    const float* b = &node.bounds[0][0][0];
    uint32_t mask = 0;
    for (int g = 0; g * 4 < N; ++g) {
        __m128 tn = l.tmin, tf = l.inf;
        for (int a = 0; a < 3; ++a) {
            const __m128 n = _mm_mul_ps(_mm_sub_ps(load_group<N>(b + l.near_row[a], g), l.org[a]), l.inv[a]);
            const __m128 f = _mm_mul_ps(_mm_sub_ps(load_group<N>(b + l.far_row[a], g), l.org[a]), l.inv[a]);
            tn = _mm_max_ps(n, tn);
            tf = _mm_min_ps(f, tf);
        }
        const __m128 pos = _mm_cmpge_ps(tf, _mm_setzero_ps());
        tf = _mm_mul_ps(tf, _mm_add_ps(l.down, _mm_and_ps(pos, l.step)));
        tf = _mm_min_ps(tf, cull4);
        _mm_store_ps(tnear + 4 * g, tn);
        mask |= uint32_t(_mm_movemask_ps(_mm_cmple_ps(tn, tf))) << (4 * g);
    }
    return mask;
}

template <int N, bool kAnyHit>
Hit trace_fused(const WideView& v, const Ray& ray, WorkCounts* work) {
    if (v.node_count == 0 || !ray_is_valid(ray)) {
        if (work) *work = WorkCounts{};
        return Hit{};
    }
    const auto* const nodes = reinterpret_cast<const WideNode<N>*>(v.nodes);
    const HwTriangle* const tris = v.triangles;
    const RayBoxPre box = ray_box_precompute(ray);
    const RayTrianglePre tri = ray_triangle_precompute(ray);
    Lanes l;
    for (int a = 0; a < 3; ++a) {
        l.org[a] = _mm_set1_ps(box.origin4[a]);
        l.inv[a] = _mm_set1_ps(box.inv_dir4[a]);
        const bool neg = std::signbit(box.inv_dir4[a]);
        l.near_row[a] = uint32_t((2 * a + (neg ? 1 : 0)) * N);
        l.far_row[a] = uint32_t((2 * a + (neg ? 0 : 1)) * N);
    }
    l.tmin = _mm_set1_ps(ray.tmin);
    l.inf = _mm_set1_ps(std::numeric_limits<float>::infinity());
    l.down = _mm_set1_ps(detail::kFarDown);
    l.step = _mm_set1_ps(detail::kFarStep);
    const float tmin = ray.tmin, tmax = ray.tmax;
    Hit best;
    best.t = tmax;
    float cull = detail::cull_distance(tmax);
    __m128 cull4 = _mm_set1_ps(cull);
    uint32_t steps = 0, box_tests = 0, tri_tests = 0, anyhit_calls = 0;
    WideStackEntry stack[kWideStackLimit];
    uint32_t size = 0, ref = 0, count = 0;
    alignas(16) float tnear[8];
    for (;;) {
        if (count == 0) {
            const WideNode<N>& node = nodes[ref];
            const uint32_t valid = valid_slots(node);
            steps += 1;
            box_tests += uint32_t(__builtin_popcount(valid));
            const uint32_t mask = node_test(l, node, cull4, tnear) & valid;
            if (mask != 0) {
                uint32_t next;
                if ((mask & (mask - 1)) == 0) {
                    next = uint32_t(__builtin_ctz(mask));
                } else {
                    uint8_t order[kMaxWideWidth];
                    const int hits = detail::order_children(mask, tnear, ChildOrder::distance, 0, order);
                    if (size + uint32_t(hits) > kWideStackLimit) throw Error("wide BVH: traversal stack overflow");
                    for (int i = hits - 1; i >= 1; --i)
                        stack[size++] = {node.child_ref[order[i]], node.child_count[order[i]], tnear[order[i]]};
                    next = order[0];
                }
                ref = node.child_ref[next];
                count = node.child_count[next];
                continue;
            }
        } else {
            tri_tests += count;
            if (detail::leaf_step<kAnyHit>(tri, tmin, tmax, tris + ref, count, best, cull, anyhit_calls)) break;
            cull4 = _mm_set1_ps(cull);
        }
        // Pop: entries entered beyond the (widened) best hit are dropped without a fetch.
        for (;;) {
            if (size == 0) goto done;
            const WideStackEntry& e = stack[--size];
            if (e.tnear > cull) continue;
            ref = e.ref;
            count = e.count;
            break;
        }
    }
done:
    if (work) {
        *work = WorkCounts{};
        work->steps = steps;
        work->box_tests = box_tests;
        work->tri_tests = tri_tests;
        work->anyhit_calls = anyhit_calls;
    }
    if (best.prim < 0) best = Hit{};
    return best;
}
#endif

}  // namespace

template <int N>
Hit trace_wide_fused(const WideView& view, const Ray& ray, TraversalMode mode, WorkCounts* work) {
#if defined(__SSE2__)
    return mode == TraversalMode::any_hit ? trace_fused<N, true>(view, ray, work) : trace_fused<N, false>(view, ray, work);
#else
    WideStepper<Fp32Codec<N>> stepper(view);
    return trace_with_stepper(stepper, ray, mode, work);
#endif
}

template Hit trace_wide_fused<4>(const WideView&, const Ray&, TraversalMode, WorkCounts*);
template Hit trace_wide_fused<6>(const WideView&, const Ray&, TraversalMode, WorkCounts*);
template Hit trace_wide_fused<8>(const WideView&, const Ray&, TraversalMode, WorkCounts*);

}  // namespace rtsim
