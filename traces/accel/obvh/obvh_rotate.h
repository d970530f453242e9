#pragma once
// Rotation into an oriented node's frame (obvh.h), shared by the build's fit and the stepper, and
// the widening of the node's boxes that keeps the test conservative.
#include <cmath>
#include <cstdint>

#include "traces/common/ray.h"

namespace rtsim {

/// An oriented node's rotation index meaning none: its boxes lie on the world's axes (RDNA 4's
/// "0x7F to disable OBB").
constexpr uint8_t kNoRotation = 0x7F;

/// m * v for a row-major 3x3 `m`, each row's products summed left to right.
inline Vec3 obb_rotate(const float* m, const Vec3& v) {
    return Vec3(m[0] * v.x + m[1] * v.y + m[2] * v.z, m[3] * v.x + m[4] * v.y + m[5] * v.z,
                m[6] * v.x + m[7] * v.y + m[8] * v.z);
}

/// How far an oriented node's boxes are widened (each side, each axis) for a ray from `origin`
/// in a scene whose points lie within `scene_radius` of the world's origin. With |m_ij| <= 1 a
/// rotated coordinate is off by at most gamma(3) |v|_1 (pbrt 3rd ed. 3.9): a vertex by
/// gamma(3) sqrt(3) R, the ray's origin by gamma(3) |o|_1, and its direction, at the t of a hit
/// point p, by gamma(3) sqrt(3) |p - o| <= gamma(3) sqrt(3) (R + |o|). So the rotated ray passes
/// within gamma(3) (2 sqrt(3) R + |o|_1 + sqrt(3) |o|) of every point of the node's triangles it
/// truly meets; twice that also covers the rounding of lo - pad and hi + pad (the pad is larger
/// than half an ulp of any coordinate within R). The slab test's own rounding is its own (Ize 2013).
inline float obb_pad(const Vec3& origin, float scene_radius) {
    constexpr double kGamma3 = 3.0 * 0x1p-24 / (1.0 - 3.0 * 0x1p-24);
    const double o1 = std::fabs(double(origin.x)) + std::fabs(double(origin.y)) + std::fabs(double(origin.z));
    const double o2 = std::sqrt(double(origin.x) * origin.x + double(origin.y) * origin.y + double(origin.z) * origin.z);
    const double sqrt3 = 1.7320508075688772;
    return float(2.0 * kGamma3 * (2.0 * sqrt3 * double(scene_radius) + o1 + sqrt3 * o2) * (1.0 + 0x1p-20));
}

}  // namespace rtsim
