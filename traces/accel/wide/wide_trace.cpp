// The fused reference loops of the fp32 wide BVHs (wide_accel.h). The loop (wide_trace_loop.inc)
// is compiled twice: with SSE2 node tests (four children per operation; the baseline ISA) and,
// for 8-wide nodes, with AVX node tests (eight per operation), chosen at run time when the CPU
// has AVX. Lane for lane the box test is detail::box_kernel (wide_fused_sse.inc), so the
// children hit, their entry distances, the visit order, the hits and every work count equal the
// stepper's. test_wide checks both instruction sets against the stepper ray by ray.
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "traces/accel/wide/wide_accel.h"

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace rtsim {
namespace {

/// Float offset in a node of the near and far plane rows of each axis (bounds[axis][side][slot]).
template <int N>
inline void fp32_rows(const RayBoxPre& box, uint32_t near_row[3], uint32_t far_row[3]) {
    for (int a = 0; a < 3; ++a) {
        const bool neg = std::signbit(box.inv_dir4[a]);
        near_row[a] = uint32_t((2 * a + (neg ? 1 : 0)) * N);
        far_row[a] = uint32_t((2 * a + (neg ? 0 : 1)) * N);
    }
}

template <int N>
inline const WideNode<N>& fp32_at(const WideView& v, uint32_t i) {
    return reinterpret_cast<const WideNode<N>*>(v.nodes)[i];
}

#if defined(__SSE2__)
namespace sse {

#include "traces/accel/wide/wide_fused_sse.inc"

/// Lanes 4g .. 4g+3 of a row of N values (N = 6, g = 1: two values, lanes 2 and 3 zero).
template <int N>
inline __m128 load_group(const float* row, int g) {
    if (N - 4 * g >= 4) return _mm_loadu_ps(row + 4 * g);
    return _mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(row + 4 * g)));
}

/// The fp32 node layout for the loop (wide_trace_loop.inc), four children per operation.
template <int N>
struct Fp32 {
    using Node = WideNode<N>;
    static const Node& at(const WideView& v, uint32_t i) { return fp32_at<N>(v, i); }
    static uint32_t valid(const WideView& v, uint32_t i, const Node&) { return v.valid[i]; }
    static void rows(const RayBoxPre& box, uint32_t* near_row, uint32_t* far_row) { fp32_rows<N>(box, near_row, far_row); }
    static uint32_t test(const Lanes& l, const Node& node, float* tnear) {
        const float* b = &node.bounds[0][0][0];
        uint32_t mask = 0;
        for (int g = 0; g * 4 < N; ++g) {
            __m128 near[3], far[3];
            for (int a = 0; a < 3; ++a) {
                near[a] = load_group<N>(b + l.near_row[a], g);
                far[a] = load_group<N>(b + l.far_row[a], g);
            }
            mask |= box_lanes(l, near, far, tnear + 4 * g) << (4 * g);
        }
        return mask;
    }
    static void child(const Node& n, uint32_t slot, uint32_t& ref, uint32_t& count) {
        ref = n.child_ref[slot];
        count = n.child_count[slot];
    }
};

#include "traces/accel/wide/wide_trace_loop.inc"

}  // namespace sse
#endif

#if defined(__x86_64__) && defined(__GNUC__)
#define RTSIM_WIDE_AVX 1
// Only the functions below are compiled for AVX (and POPCNT, which every AVX CPU has: the loop
// counts each node's box tests with it, lane_count); they are internal to this file, so no AVX
// code can be chosen by the linker for a caller elsewhere (inline functions of the headers above
// are compiled for the baseline and inlined here).
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx,popcnt"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx,popcnt")
#endif
namespace avx {

#include "traces/accel/wide/wide_fused_avx.inc"

/// The 8-wide fp32 node on eight lanes: one operation per plane of all children.
struct Fp32x8 {
    using Node = WideNode<8>;
    static const Node& at(const WideView& v, uint32_t i) { return fp32_at<8>(v, i); }
    static uint32_t valid(const WideView& v, uint32_t i, const Node&) { return v.valid[i]; }
    static void rows(const RayBoxPre& box, uint32_t* near_row, uint32_t* far_row) { fp32_rows<8>(box, near_row, far_row); }
    static uint32_t test(const Lanes& l, const Node& node, float* tnear) {
        const float* b = &node.bounds[0][0][0];
        __m256 near[3], far[3];
        for (int a = 0; a < 3; ++a) {
            near[a] = _mm256_loadu_ps(b + l.near_row[a]);
            far[a] = _mm256_loadu_ps(b + l.far_row[a]);
        }
        return box_lanes(l, near, far, tnear);
    }
    static void child(const Node& n, uint32_t slot, uint32_t& ref, uint32_t& count) {
        ref = n.child_ref[slot];
        count = n.child_count[slot];
    }
};

#include "traces/accel/wide/wide_trace_loop.inc"

}  // namespace avx
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif
#endif

}  // namespace

/// AVX (or AVX2) when the CPU has it, unless RTSIM_SIMD=sse2 asks for the baseline (benchmarks
/// compare).
bool wide_simd_has(const char* feature) {
#if defined(__x86_64__) && defined(__GNUC__)
    const char* env = std::getenv("RTSIM_SIMD");
    if (env && std::strcmp(env, "sse2") == 0) return false;
    __builtin_cpu_init();
    if (std::strcmp(feature, "avx") == 0) return __builtin_cpu_supports("avx");
    if (std::strcmp(feature, "avx2") == 0) return __builtin_cpu_supports("avx2");
    if (std::strcmp(feature, "popcnt") == 0) return __builtin_cpu_supports("popcnt");
    if (std::strcmp(feature, "fma") == 0) return __builtin_cpu_supports("fma");
#endif
    (void)feature;
    return false;
}

bool wide_simd_has_avx() {
    static const bool has = wide_simd_has("avx") && wide_simd_has("popcnt");
    return has;
}

template <int N>
Hit trace_wide_fused(const WideView& view, const Ray& ray, TraversalMode mode, WorkCounts* work, WideSimd simd) {
    const bool any = mode == TraversalMode::any_hit;
#if defined(RTSIM_WIDE_AVX)
    if constexpr (N == 8) {
        if (simd != WideSimd::sse2 && view.valid && wide_simd_has_avx())
            return any ? avx::trace_fused<avx::Fp32x8, true>(view, ray, work)
                       : avx::trace_fused<avx::Fp32x8, false>(view, ray, work);
    }
#endif
#if defined(__SSE2__)
    if (view.valid)
        return any ? sse::trace_fused<sse::Fp32<N>, true>(view, ray, work)
                   : sse::trace_fused<sse::Fp32<N>, false>(view, ray, work);
#endif
    WideStepper<Fp32Codec<N>> stepper(view);
    return trace_with_stepper(stepper, ray, mode, work);
}

template Hit trace_wide_fused<4>(const WideView&, const Ray&, TraversalMode, WorkCounts*, WideSimd);
template Hit trace_wide_fused<6>(const WideView&, const Ray&, TraversalMode, WorkCounts*, WideSimd);
template Hit trace_wide_fused<8>(const WideView&, const Ray&, TraversalMode, WorkCounts*, WideSimd);

template <int N>
Hit Fp32Codec<N>::fused(const WideView& view, const Ray& ray, TraversalMode mode, WorkCounts* work) {
    return trace_wide_fused<N>(view, ray, mode, work);
}
template struct Fp32Codec<4>;
template struct Fp32Codec<6>;
template struct Fp32Codec<8>;

}  // namespace rtsim
