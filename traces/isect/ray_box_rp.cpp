// The reduced-precision, conservative box test (ray_box_rp.h).
#include "traces/isect/ray_box_rp.h"

#include <cmath>
#include <limits>

#include "traces/isect/ray_box_kernel.h"

namespace rtsim {

namespace {

/// Relative bound on the fp32 test's slab-distance error (a subtraction and a multiply, each
/// rounded to nearest: < 2 * 2^-24), with margin.
constexpr double kFp32SlabError = 0x1p-21;

/// Moves a finite x away from the value it bounds: down (lower bound) or up (upper bound) by
/// `rel` of its magnitude.
double widen(double x, double rel, bool up) {
    if (!std::isfinite(x)) return x;
    const double d = std::fabs(x) * rel;
    return up ? x + d : x - d;
}

/// A slab distance (plane - origin) * inv, rounded outward at every step: its lower bound when
/// `up` is false, its upper bound otherwise. `plane` is already on the p-bit grid.
double slab_bound(double plane, double origin, double inv, uint32_t bits, bool up) {
    // The difference of two floats is exact in double unless their exponents are far apart; the
    // widening covers that rounding too. A bound on t needs the difference's same bound when
    // inv >= 0 and its opposite when inv < 0.
    const bool diff_up = up != std::signbit(inv);
    const double diff = round_mantissa(widen(plane - origin, 0x1p-50, diff_up), bits, diff_up);
    if (std::isinf(inv)) return diff * inv;  // 0 * inf is NaN: ignored, as in the fp32 test
    const double inv_lo = round_mantissa(inv, bits, false), inv_hi = round_mantissa(inv, bits, true);
    const double a = diff * inv_lo, b = diff * inv_hi;  // exact: two p-bit mantissas fit in a double
    const double t = up ? std::fmax(a, b) : std::fmin(a, b);
    return round_mantissa(widen(t, kFp32SlabError, up), bits, up);
}

}  // namespace

double round_mantissa(double x, uint32_t bits, bool up) {
    if (x == 0.0 || !std::isfinite(x)) return x;
    int e = 0;
    const double m = std::frexp(x, &e);  // x = m * 2^e, 0.5 <= |m| < 1
    const double scale = std::ldexp(1.0, int(bits) + 1);
    const double q = up ? std::ceil(m * scale) : std::floor(m * scale);
    return std::ldexp(q, e - int(bits) - 1);
}

bool intersect_box_rp(const RayBoxPre& pre, const float lo[3], const float hi[3], float tmin, float tmax,
                      uint32_t bits, float* tnear) {
    double tn = tmin;
    double tf = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        const bool neg = std::signbit(pre.inv_dir4[a]);
        const double lo_q = round_mantissa(lo[a], bits, false), hi_q = round_mantissa(hi[a], bits, true);
        const double n = slab_bound(neg ? hi_q : lo_q, pre.origin4[a], pre.inv_dir4[a], bits, false);
        const double f = slab_bound(neg ? lo_q : hi_q, pre.origin4[a], pre.inv_dir4[a], bits, true);
        tn = n > tn ? n : tn;  // NaN-ignoring, as the fp32 fold
        tf = f < tf ? f : tf;
    }
    tf = widen(tf, 2.0 * detail::kGamma3, true);  // the fp32 test's far scale, at least
    tf = tf < double(tmax) ? tf : double(tmax);
    // tn is tmin or a p-bit value with fp32's exponent range: exact as a float unless it
    // overflows, where it bounds nothing the ray can reach.
    *tnear = float(tn);
    return tn <= tf;
}

}  // namespace rtsim
