// The fused reference loop of the compressed 8-wide BVH (cwbvh8, CwNode8): the wide loop
// (traces/accel/wide/wide_trace_loop.inc) on a node policy that dequantises each axis's near and
// far planes of all eight children at once, straight from the node's bytes, once per node step.
// Lane for lane the decoding is quant_decode (quantize.h): p + float(q) * 2^(e - 127), the
// integer-to-float conversion exact and the product exact, the sum rounded once; the box test is
// the fp32 loop's (wide_fused_*.inc). So the children hit, their entry distances and every hit
// and work count equal WideStepper<Cw8Codec>'s; test_cwbvh and test_wide check both instruction
// sets against the stepper ray by ray. SSE2 decodes four children per operation (the baseline);
// AVX2, when the CPU has it, eight (its byte-to-int widening is what AVX lacks), with the decode's
// multiply-add fused where that is exact (decode8).
#include <cmath>
#include <cstddef>
#include <cstring>

#include "traces/accel/cwbvh/cwbvh.h"

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace rtsim {
namespace {

/// Byte offsets in a CwNode8 of each axis's near and far quantised rows (qlo or qhi).
inline void cw8_rows(const RayBoxPre& box, uint32_t near_row[3], uint32_t far_row[3]) {
    for (int a = 0; a < 3; ++a) {
        const bool neg = std::signbit(box.inv_dir4[a]);
        const uint32_t lo = uint32_t(offsetof(CwNode8, qlo)) + 8 * a, hi = uint32_t(offsetof(CwNode8, qhi)) + 8 * a;
        near_row[a] = neg ? hi : lo;
        far_row[a] = neg ? lo : hi;
    }
}

inline const CwNode8& cw8_at(const WideView& v, uint32_t i) { return reinterpret_cast<const CwNode8*>(v.nodes)[i]; }

#if defined(__SSE2__)
/// The slots holding a child (meta byte not 0), from the node's own first line: Cw8Codec::valid_mask.
inline uint32_t cw8_valid(const CwNode8& n) {
    const __m128i meta = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(n.meta));
    return ~uint32_t(_mm_movemask_epi8(_mm_cmpeq_epi8(meta, _mm_setzero_si128()))) & 0xFFu;
}
#endif

/// Child `slot` as Cw8Codec::decode gives it: an interior child (imask, which validation holds
/// equal to the meta bytes' interiors) is node base_node + the interior children in lower slots;
/// a leaf, meta_leaf_count(meta) triangles from base_tri + its offset. Selects, not branches.
/// The two bit counts come from the caller, which counts cw8_child_bits with its instruction
/// set's popcount: this is on the chain from one node to the next, and a popcount passed in as a
/// function would stay a call (this function is compiled for the baseline, an AVX2 one cannot be
/// inlined into it; that call cost cwbvh8 about 10% on primary rays).
struct Cw8ChildBits {
    uint32_t lower_interiors;  // imask bits below the slot
    uint32_t unary_count;      // the meta byte's top 3 bits: a leaf's count in unary
};
inline Cw8ChildBits cw8_child_bits(const CwNode8& n, uint32_t slot) {
    return {n.imask & ((1u << slot) - 1u), uint32_t(n.meta[slot]) >> 5};
}
inline void cw8_child(const CwNode8& n, uint32_t slot, uint32_t lower_interiors_count, uint32_t leaf_count,
                      uint32_t& ref, uint32_t& count) {
    const bool interior = (n.imask >> slot) & 1u;
    ref = interior ? n.base_node + lower_interiors_count : n.base_tri + meta_leaf_offset(n.meta[slot]);
    count = interior ? 0u : leaf_count;
}

#if defined(__SSE2__)
namespace sse {

#include "traces/accel/wide/wide_fused_sse.inc"

/// quant_decode of four bytes q[0..3] on four lanes.
inline __m128 decode4(const uint8_t* q, __m128 p, __m128 scale) {
    int32_t bytes;
    std::memcpy(&bytes, q, 4);
    const __m128i zero = _mm_setzero_si128();
    const __m128i x = _mm_unpacklo_epi16(_mm_unpacklo_epi8(_mm_cvtsi32_si128(bytes), zero), zero);
    return _mm_add_ps(p, _mm_mul_ps(_mm_cvtepi32_ps(x), scale));
}

struct Cw8 {
    using Node = CwNode8;
    static const Node& at(const WideView& v, uint32_t i) { return cw8_at(v, i); }
    static uint32_t valid(const WideView&, uint32_t, const Node& n) { return cw8_valid(n); }
    static void rows(const RayBoxPre& box, uint32_t* near_row, uint32_t* far_row) { cw8_rows(box, near_row, far_row); }
    static uint32_t test(const Lanes& l, const Node& node, float* tnear) {
        const uint8_t* bytes = reinterpret_cast<const uint8_t*>(&node);
        __m128 p[3], scale[3];
        for (int a = 0; a < 3; ++a) {
            p[a] = _mm_set1_ps(node.p[a]);
            scale[a] = _mm_set1_ps(quant_scale(node.e[a]));
        }
        uint32_t mask = 0;
        for (int g = 0; g < 2; ++g) {
            __m128 near[3], far[3];
            for (int a = 0; a < 3; ++a) {
                near[a] = decode4(bytes + l.near_row[a] + 4 * g, p[a], scale[a]);
                far[a] = decode4(bytes + l.far_row[a] + 4 * g, p[a], scale[a]);
            }
            mask |= box_lanes(l, near, far, tnear + 4 * g) << (4 * g);
        }
        return mask;
    }
    static void child(const Node& n, uint32_t slot, uint32_t& ref, uint32_t& count) {
        const Cw8ChildBits b = cw8_child_bits(n, slot);
        cw8_child(n, slot, detail::popcount8(b.lower_interiors), detail::popcount8(b.unary_count), ref, count);
    }
};

#include "traces/accel/wide/wide_trace_loop.inc"

}  // namespace sse
#endif

#if defined(__x86_64__) && defined(__GNUC__)
#define RTSIM_CW_AVX2 1
// Only the functions below are compiled for AVX2 (and FMA and POPCNT, which every AVX2 CPU has),
// internal to this file (see wide_trace.cpp).
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2,fma,popcnt"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2,fma,popcnt")
#endif
namespace avx {

#include "traces/accel/wide/wide_fused_avx.inc"

/// quant_decode of eight bytes q[0..7] on eight lanes. With `fused`, as one fused multiply-add:
/// float(q) * scale is exact (8 significant bits times a power of two, never subnormal since
/// q >= 1 and scale >= 2^-126) unless it overflows, so p + q * scale rounds once either way and
/// the FMA is bit for bit quant_decode. The caller asks for it only when no exponent byte of the
/// node exceeds 247, where 255 * scale < FLT_MAX.
inline __m256 decode8(const uint8_t* q, __m256 p, __m256 scale, bool fused) {
    const __m256 x = _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(q))));
    return fused ? _mm256_fmadd_ps(x, scale, p) : _mm256_add_ps(p, _mm256_mul_ps(x, scale));
}

struct Cw8 {
    using Node = CwNode8;
    static const Node& at(const WideView& v, uint32_t i) { return cw8_at(v, i); }
    static uint32_t valid(const WideView&, uint32_t, const Node& n) { return cw8_valid(n); }
    static void rows(const RayBoxPre& box, uint32_t* near_row, uint32_t* far_row) { cw8_rows(box, near_row, far_row); }
    static uint32_t test(const Lanes& l, const Node& node, float* tnear) {
        const uint8_t* bytes = reinterpret_cast<const uint8_t*>(&node);
        // The three scales 2^(e - 127) at once: the exponent bytes widened and shifted into place.
        int32_t e_bytes;  // e[0..2] and imask
        std::memcpy(&e_bytes, bytes + offsetof(CwNode8, e), 4);
        const __m128i e = _mm_cvtepu8_epi32(_mm_cvtsi32_si128(e_bytes));
        const bool fused = (_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpgt_epi32(e, _mm_set1_epi32(247)))) & 7) == 0;
        const __m128 scales = _mm_castsi128_ps(_mm_slli_epi32(e, 23));
        const __m256 scale[3] = {_mm256_broadcastss_ps(scales),
                                 _mm256_broadcastss_ps(_mm_shuffle_ps(scales, scales, 0x55)),
                                 _mm256_broadcastss_ps(_mm_shuffle_ps(scales, scales, 0xAA))};
        __m256 near[3], far[3];
        for (int a = 0; a < 3; ++a) {
            const __m256 p = _mm256_broadcast_ss(&node.p[a]);
            near[a] = decode8(bytes + l.near_row[a], p, scale[a], fused);
            far[a] = decode8(bytes + l.far_row[a], p, scale[a], fused);
        }
        return box_lanes(l, near, far, tnear);
    }
    static void child(const Node& n, uint32_t slot, uint32_t& ref, uint32_t& count) {
        const Cw8ChildBits b = cw8_child_bits(n, slot);
        cw8_child(n, slot, uint32_t(__builtin_popcount(b.lower_interiors)), uint32_t(__builtin_popcount(b.unary_count)),
                  ref, count);
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

Hit trace_cwbvh8_fused(const WideView& view, const Ray& ray, TraversalMode mode, WorkCounts* work, WideSimd simd) {
    const bool any = mode == TraversalMode::any_hit;
#if defined(RTSIM_CW_AVX2)
    static const bool has_avx2 = wide_simd_has("avx2") && wide_simd_has("fma") && wide_simd_has("popcnt");
    if (simd != WideSimd::sse2 && view.valid && has_avx2)
        return any ? avx::trace_fused<avx::Cw8, true>(view, ray, work) : avx::trace_fused<avx::Cw8, false>(view, ray, work);
#endif
#if defined(__SSE2__)
    if (view.valid)
        return any ? sse::trace_fused<sse::Cw8, true>(view, ray, work) : sse::trace_fused<sse::Cw8, false>(view, ray, work);
#endif
    (void)simd;
    WideStepper<Cw8Codec> stepper(view);
    return trace_with_stepper(stepper, ray, mode, work);
}

template <>
Hit Cw8Codec::fused(const WideView& view, const Ray& ray, TraversalMode mode, WorkCounts* work) {
    return trace_cwbvh8_fused(view, ray, mode, work);
}

}  // namespace rtsim
