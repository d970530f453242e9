// The fused reference loops of the fp32 wide BVHs (wide_accel.h). The loop (wide_trace_loop.inc)
// is compiled twice: with SSE2 node tests (four children per operation; the baseline ISA) and,
// for 8-wide nodes, with AVX node tests (eight per operation), chosen at run time when the CPU
// has AVX. Lane for lane the box test is detail::box_kernel (traces/isect/ray_box_kernel.h): the
// same IEEE operations in the same order (MAXPS/MINPS and their VEX forms return the second
// operand on NaN, the kernel's NaN-ignoring fold; no FMA), so the children hit, their entry
// distances, the visit order, the hits and every work count equal the stepper's. test_wide checks
// both instruction sets against the stepper ray by ray.
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "traces/accel/wide/wide_accel.h"

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace rtsim {
namespace {

#if defined(__SSE2__)
/// Starts loading a pushed child (its node's first two lines, or its triangles) while the nearer
/// subtree is traversed: the loop's time goes mostly to waiting for nodes and triangles.
template <int N>
inline void prefetch_child(const WideView& v, uint32_t ref, uint32_t count) {
    const char* p = count == 0 ? reinterpret_cast<const char*>(v.nodes + uint64_t(ref) * sizeof(WideNode<N>))
                               : reinterpret_cast<const char*>(v.triangles + ref);
    _mm_prefetch(p, _MM_HINT_T0);
    _mm_prefetch(p + 64, _MM_HINT_T0);
}

namespace sse {

/// The ray's constants for the node test.
struct Lanes {
    __m128 org[3], inv[3], tmin, inf, down, step, cull;
    uint32_t near_row[3], far_row[3];  ///< float offsets of each axis's near and far plane rows
};

/// Float offset in a node of the near and far plane rows of each axis (bounds[axis][side][slot]).
template <int N>
inline void plane_rows(const RayBoxPre& box, uint32_t near_row[3], uint32_t far_row[3]) {
    for (int a = 0; a < 3; ++a) {
        const bool neg = std::signbit(box.inv_dir4[a]);
        near_row[a] = uint32_t((2 * a + (neg ? 1 : 0)) * N);
        far_row[a] = uint32_t((2 * a + (neg ? 0 : 1)) * N);
    }
}

template <int N>
inline Lanes make_lanes(const RayBoxPre& box, const Ray& ray) {
    Lanes l;
    for (int a = 0; a < 3; ++a) {
        l.org[a] = _mm_set1_ps(box.origin4[a]);
        l.inv[a] = _mm_set1_ps(box.inv_dir4[a]);
    }
    plane_rows<N>(box, l.near_row, l.far_row);
    l.tmin = _mm_set1_ps(ray.tmin);
    l.inf = _mm_set1_ps(std::numeric_limits<float>::infinity());
    l.down = _mm_set1_ps(detail::kFarDown);
    l.step = _mm_set1_ps(detail::kFarStep);
    return l;
}

inline void set_cull(Lanes& l, float cull) { l.cull = _mm_set1_ps(cull); }

/// Lanes 4g .. 4g+3 of a row of N values (N = 6, g = 1: two values, lanes 2 and 3 zero).
template <int N>
inline __m128 load_group(const float* row, int g) {
    if (N - 4 * g >= 4) return _mm_loadu_ps(row + 4 * g);
    return _mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(row + 4 * g)));
}

/// Every child box of a node against [tmin, cull]: the hit mask; entry distances in tnear.
template <int N>
inline uint32_t node_test(const Lanes& l, const WideNode<N>& node, float* tnear) {
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
        tf = _mm_min_ps(tf, l.cull);
        _mm_store_ps(tnear + 4 * g, tn);
        mask |= uint32_t(_mm_movemask_ps(_mm_cmple_ps(tn, tf))) << (4 * g);
    }
    return mask;
}

#include "traces/accel/wide/wide_trace_loop.inc"

}  // namespace sse
#endif

#if defined(__x86_64__) && defined(__GNUC__)
#define RTSIM_WIDE_AVX 1
// Only the functions below are compiled for AVX; they are internal to this file, so no AVX code
// can be chosen by the linker for a caller elsewhere (inline functions of the headers above are
// compiled for the baseline and inlined here).
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx")
#endif
namespace avx {

struct Lanes {
    __m256 org[3], inv[3], tmin, inf, down, step, cull;
    uint32_t near_row[3], far_row[3];
};

template <int N>
inline Lanes make_lanes(const RayBoxPre& box, const Ray& ray) {
    static_assert(N == 8, "the AVX node test is for 8-wide nodes");
    Lanes l;
    for (int a = 0; a < 3; ++a) {
        l.org[a] = _mm256_set1_ps(box.origin4[a]);
        l.inv[a] = _mm256_set1_ps(box.inv_dir4[a]);
    }
    sse::plane_rows<N>(box, l.near_row, l.far_row);
    l.tmin = _mm256_set1_ps(ray.tmin);
    l.inf = _mm256_set1_ps(std::numeric_limits<float>::infinity());
    l.down = _mm256_set1_ps(detail::kFarDown);
    l.step = _mm256_set1_ps(detail::kFarStep);
    return l;
}

inline void set_cull(Lanes& l, float cull) { l.cull = _mm256_set1_ps(cull); }

/// The SSE node test on eight lanes: the same operations in the same order.
template <int N>
inline uint32_t node_test(const Lanes& l, const WideNode<N>& node, float* tnear) {
    const float* b = &node.bounds[0][0][0];
    __m256 tn = l.tmin, tf = l.inf;
    for (int a = 0; a < 3; ++a) {
        const __m256 n = _mm256_mul_ps(_mm256_sub_ps(_mm256_loadu_ps(b + l.near_row[a]), l.org[a]), l.inv[a]);
        const __m256 f = _mm256_mul_ps(_mm256_sub_ps(_mm256_loadu_ps(b + l.far_row[a]), l.org[a]), l.inv[a]);
        tn = _mm256_max_ps(n, tn);
        tf = _mm256_min_ps(f, tf);
    }
    const __m256 pos = _mm256_cmp_ps(tf, _mm256_setzero_ps(), _CMP_GE_OQ);
    tf = _mm256_mul_ps(tf, _mm256_add_ps(l.down, _mm256_and_ps(pos, l.step)));
    tf = _mm256_min_ps(tf, l.cull);
    _mm256_store_ps(tnear, tn);
    return uint32_t(_mm256_movemask_ps(_mm256_cmp_ps(tn, tf, _CMP_LE_OQ)));
}

#include "traces/accel/wide/wide_trace_loop.inc"

}  // namespace avx
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif

/// AVX when the CPU has it, unless RTSIM_SIMD=sse2 asks for the baseline (benchmarks compare).
bool cpu_has_avx() {
    static const bool has = [] {
        const char* env = std::getenv("RTSIM_SIMD");
        return __builtin_cpu_supports("avx") && !(env && std::strcmp(env, "sse2") == 0);
    }();
    return has;
}
#endif

}  // namespace

template <int N>
Hit trace_wide_fused(const WideView& view, const Ray& ray, TraversalMode mode, WorkCounts* work, WideSimd simd) {
    const bool any = mode == TraversalMode::any_hit;
#if defined(RTSIM_WIDE_AVX)
    if constexpr (N == 8) {
        if (simd != WideSimd::sse2 && view.valid && cpu_has_avx())
            return any ? avx::trace_fused<8, true>(view, ray, work) : avx::trace_fused<8, false>(view, ray, work);
    }
#endif
#if defined(__SSE2__)
    if (view.valid) return any ? sse::trace_fused<N, true>(view, ray, work) : sse::trace_fused<N, false>(view, ray, work);
#endif
    WideStepper<Fp32Codec<N>> stepper(view);
    return trace_with_stepper(stepper, ray, mode, work);
}

bool wide_simd_has_avx() {
#if defined(RTSIM_WIDE_AVX)
    return cpu_has_avx();
#else
    return false;
#endif
}

template Hit trace_wide_fused<4>(const WideView&, const Ray&, TraversalMode, WorkCounts*, WideSimd);
template Hit trace_wide_fused<6>(const WideView&, const Ray&, TraversalMode, WorkCounts*, WideSimd);
template Hit trace_wide_fused<8>(const WideView&, const Ray&, TraversalMode, WorkCounts*, WideSimd);

}  // namespace rtsim
