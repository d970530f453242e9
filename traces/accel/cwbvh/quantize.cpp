// Outward-rounding quantisation of child boxes (quantize.h; Ylitie, Karras & Laine 2017, 3.3).
#include "traces/accel/cwbvh/quantize.h"

#include <algorithm>
#include <cmath>
#include <cstring>

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

}  // namespace rtsim
