// Outward-rounding quantisation of child boxes (quantize.h; Ylitie, Karras & Laine 2017, 3.3).
#include "traces/accel/cwbvh/quantize.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "traces/common/error.h"

namespace rtsim {

QuantFrame make_quant_frame(const Aabb& box) {
    QuantFrame f;
    for (int a = 0; a < 3; ++a) {
        require(std::isfinite(box.lo[a]) && std::isfinite(box.hi[a]) && box.lo[a] <= box.hi[a],
                "quantisation frame of an empty or non-finite box");
        f.p[a] = box.lo[a];
        // First guess from the exact extent (in double: hi - lo may overflow a float), then the
        // smallest exponent byte whose decoded q = 255 reaches hi; decoding rounds, so check it.
        const double step = (double(box.hi[a]) - double(box.lo[a])) / 255.0;
        int e = step > 0.0 ? int(std::ceil(std::log2(step))) + 127 : 1;
        e = std::clamp(e, 1, 254);
        while (e < 254 && quant_decode(f.p[a], uint8_t(e), 255) < box.hi[a]) ++e;
        while (e > 1 && quant_decode(f.p[a], uint8_t(e - 1), 255) >= box.hi[a]) --e;
        f.e[a] = uint8_t(e);
    }
    return f;
}

namespace {

/// (x - p) / scale in double, clamped to [0, 255]: exact before the clamp (scale is a power of
/// two, so its inverse is exact too), a starting point the walks below correct by a step or two.
double steps_from_origin(const QuantFrame& f, int a, float x) {
    const uint64_t bits = uint64_t(1023 + 127 - int(f.e[a])) << 52;  // 2^(127 - e) as a double
    double inv_scale;
    std::memcpy(&inv_scale, &bits, sizeof inv_scale);
    return std::clamp((double(x) - double(f.p[a])) * inv_scale, 0.0, 255.0);
}

}  // namespace

uint8_t quantize_lo(const QuantFrame& f, int a, float lo) {
    int q = int(steps_from_origin(f, a, lo));  // truncation: the floor of a value >= 0
    // decode is monotone in q: walk to the largest q that still decodes at or below lo.
    while (q > 0 && quant_decode(f.p[a], f.e[a], uint32_t(q)) > lo) --q;
    while (q < 255 && quant_decode(f.p[a], f.e[a], uint32_t(q + 1)) <= lo) ++q;
    require(quant_decode(f.p[a], f.e[a], uint32_t(q)) <= lo, "quantize_lo: bound below the frame's origin");
    return uint8_t(q);
}

uint8_t quantize_hi(const QuantFrame& f, int a, float hi) {
    const double steps = steps_from_origin(f, a, hi);
    int q = int(steps);
    q += double(q) < steps;  // the ceiling
    while (q < 255 && quant_decode(f.p[a], f.e[a], uint32_t(q)) < hi) ++q;
    while (q > 0 && quant_decode(f.p[a], f.e[a], uint32_t(q - 1)) >= hi) --q;
    require(quant_decode(f.p[a], f.e[a], uint32_t(q)) >= hi, "quantize_hi: bound beyond the frame");
    return uint8_t(q);
}

#if defined(__SSE2__)
namespace {

/// quant_decode of the lanes of q (0..255 as int32) on the frame's axis.
inline __m128 decode4(__m128 p, __m128 scale, __m128i q) { return _mm_add_ps(p, _mm_mul_ps(_mm_cvtepi32_ps(q), scale)); }

/// Four bounds quantised outward (lo: round_down, else up) by the scalar functions' rule, with
/// their walk done as two steps each way on all lanes; a lane the steps did not settle (the
/// answer is unique: decode is monotone in q) is left to the scalar function (returns its mask).
uint32_t quantize4(__m128 p, __m128 scale, __m128 inv_scale, __m128 bound, bool round_down, __m128i* out) {
    const __m128i zero = _mm_setzero_si128(), top = _mm_set1_epi32(255), one = _mm_set1_epi32(1);
    const __m128 steps = _mm_min_ps(_mm_max_ps(_mm_mul_ps(_mm_sub_ps(bound, p), inv_scale), _mm_setzero_ps()),
                                    _mm_set1_ps(255.0f));
    __m128i q = _mm_cvttps_epi32(steps);  // a guess at most a step or two off
    auto clamp = [&](__m128i x) {  // to 0..255 (SSE2 has no 32-bit integer min/max)
        x = _mm_and_si128(x, _mm_cmpgt_epi32(x, _mm_set1_epi32(-1)));
        const __m128i big = _mm_cmpgt_epi32(x, top);
        return _mm_or_si128(_mm_andnot_si128(big, x), _mm_and_si128(big, top));
    };
    // lo: the largest q decoding to <= bound; hi: the smallest decoding to >= bound.
    auto fits = [&](__m128i x) {
        const __m128 d = decode4(p, scale, x);
        return _mm_castps_si128(round_down ? _mm_cmple_ps(d, bound) : _mm_cmpge_ps(d, bound));
    };
    for (int i = 0; i < 2; ++i) {  // away from the bound while q does not fit
        const __m128i step = round_down ? one : _mm_sub_epi32(zero, one);
        q = clamp(_mm_sub_epi32(q, _mm_andnot_si128(fits(q), step)));
    }
    for (int i = 0; i < 2; ++i) {  // towards it while the next q still fits
        const __m128i next = round_down ? _mm_add_epi32(q, one) : _mm_sub_epi32(q, one);
        const __m128i in_range = round_down ? _mm_cmpgt_epi32(top, q) : _mm_cmpgt_epi32(q, zero);
        q = _mm_sub_epi32(q, _mm_and_si128(_mm_and_si128(in_range, fits(next)), round_down ? _mm_sub_epi32(zero, one) : one));
    }
    // Settled: q fits, and the next one does not (or q is at the end of the range).
    const __m128i next = round_down ? _mm_add_epi32(q, one) : _mm_sub_epi32(q, one);
    const __m128i at_end = round_down ? _mm_cmpeq_epi32(q, top) : _mm_cmpeq_epi32(q, zero);
    const __m128i settled = _mm_and_si128(fits(q), _mm_or_si128(at_end, _mm_andnot_si128(fits(next), _mm_set1_epi32(-1))));
    *out = q;
    return ~uint32_t(_mm_movemask_ps(_mm_castsi128_ps(settled))) & 15u;
}

}  // namespace

void quantize_bounds(const QuantFrame& f, int a, const float* lo, const float* hi, uint32_t count, uint8_t* q_lo,
                     uint8_t* q_hi) {
    const float scale = quant_scale(f.e[a]);
    const __m128 p = _mm_set1_ps(f.p[a]), s = _mm_set1_ps(scale), inv = _mm_set1_ps(1.0f / scale);
    for (uint32_t g = 0; g < count; g += 4) {
        const uint32_t n = count - g < 4 ? count - g : 4;
        alignas(16) float l[4], h[4];
        alignas(16) int32_t ql[4], qh[4];
        for (uint32_t i = 0; i < 4; ++i) l[i] = lo[g + (i < n ? i : 0)], h[i] = hi[g + (i < n ? i : 0)];
        __m128i x;
        const uint32_t lo_left = quantize4(p, s, inv, _mm_load_ps(l), true, &x);
        _mm_store_si128(reinterpret_cast<__m128i*>(ql), x);
        const uint32_t hi_left = quantize4(p, s, inv, _mm_load_ps(h), false, &x);
        _mm_store_si128(reinterpret_cast<__m128i*>(qh), x);
        for (uint32_t i = 0; i < n; ++i) {
            q_lo[g + i] = lo_left >> i & 1u ? quantize_lo(f, a, l[i]) : uint8_t(ql[i]);
            q_hi[g + i] = hi_left >> i & 1u ? quantize_hi(f, a, h[i]) : uint8_t(qh[i]);
        }
    }
}
#else
void quantize_bounds(const QuantFrame& f, int a, const float* lo, const float* hi, uint32_t count, uint8_t* q_lo,
                     uint8_t* q_hi) {
    for (uint32_t i = 0; i < count; ++i) q_lo[i] = quantize_lo(f, a, lo[i]), q_hi[i] = quantize_hi(f, a, hi[i]);
}
#endif

}  // namespace rtsim
