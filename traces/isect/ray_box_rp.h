#pragma once
// A reduced-precision, conservative ray/box test (docs/accel.md, "Reduced-precision box tests"):
// what a narrower box pipeline accepts, so a stepper can count the extra work it causes.
//
// Keely 2014 ("Reduced Precision for Hardware Ray Tracing in GPUs", HPG) and Vaidyanathan et al.
// 2016 ("Watertight Ray Traversal with Reduced Precision", HPG) build the box test from adders
// and multipliers with a few mantissa bits, every rounding directed so the test is conservative:
// it may accept boxes the ray misses, never reject one it hits. We model a p-bit mantissa (`bits`
// explicit fraction bits, fp32 has 23; exponent range as fp32) with every value rounded outward:
//   - the box's planes to the p-bit grid (lo down, hi up: the stored box only grows),
//   - plane - origin and the slab distance (plane - origin) * (1/d) after each operation,
//   - the reciprocal direction as the interval of its two p-bit neighbours,
// and the slab distances widened by the fp32 test's own rounding bound (2^-21 relative, more than
// its two roundings) before rounding, with the fp32 far scale 1 + 2*gamma(3) of ray_box_kernel.h.
// So every slab's near distance is <= the fp32 test's and its far distance >= it: the test accepts
// every box the fp32 test (traces/isect/ray_box_kernel.h) accepts, and its entry distance is never
// larger (tests/cpp/isect/test_ray_box_rp.cpp checks both on random rays and boxes).
// NaN convention as the fp32 test: a 0 * inf slab distance is ignored.
#include <cstdint>

#include "traces/isect/ray_box.h"

namespace rtsim {

/// Explicit mantissa bits of the reduced-precision box test (traversal.box_precision_bits):
/// 0 turns it off (the fp32 test alone), otherwise 1..kMaxBoxPrecisionBits.
constexpr uint32_t kMaxBoxPrecisionBits = 22;

/// x rounded to `bits` explicit mantissa bits, down (towards -inf) or up; 0, inf and NaN unchanged.
double round_mantissa(double x, uint32_t bits, bool up);

/// The reduced-precision test of one box against [tmin, tmax] (bits >= 1). Returns hit and writes
/// its entry distance (<= the fp32 test's wherever that one hits).
bool intersect_box_rp(const RayBoxPre& pre, const float lo[3], const float hi[3], float tmin, float tmax,
                      uint32_t bits, float* tnear);

}  // namespace rtsim
