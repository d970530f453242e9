#pragma once
// Ray/sphere intersection, inline for the traversal's hot loop (docs/intersection.md,
// "Ray/sphere"). Haines, Guenther & Akenine-Moeller 2019, "Precision Improvements for Ray/Sphere
// Intersection" (Ray Tracing Gems, chapter 7): the discriminant from the squared distance of the
// sphere's centre to the ray's line (no cancellation of b^2 against 4ac for small or distant
// spheres), and the nearer root as c/q with q = -(b + sign(b) sqrt(discriminant)) (no
// cancellation between b and the root). All in double from float inputs: the differences of
// float coordinates are exact there, so huge and tiny coordinates keep their digits.
#include <cmath>
#include <utility>

#include "traces/isect/ray_triangle.h"

namespace rtsim {
namespace detail {

/// Sphere coordinates of a unit normal, in [0, 1): u the longitude about +z, v the colatitude.
inline void sphere_uv(double nx, double ny, double nz, float* u, float* v) {
    constexpr double kPi = 3.14159265358979323846;
    double phi = std::atan2(ny, nx);
    if (phi < 0.0) phi += 2.0 * kPi;
    const double cz = nz < -1.0 ? -1.0 : (nz > 1.0 ? 1.0 : nz);
    *u = float(phi / (2.0 * kPi));
    *v = float(std::acos(cz) / kPi);
    if (!(*u < 1.0f)) *u = 0.0f;  // phi rounded up to 2 pi
}

/// True if the ray hits the sphere (centre c, radius r) at tmin < t <= tmax: the nearer of the
/// two crossings inside the interval (the far one for a ray starting inside). A tangent ray hits
/// at its one point of contact; a sphere of radius 0 (or not finite) is never hit. hit->u, v are
/// the hit point's sphere coordinates (sphere_uv).
inline bool sphere_kernel(const RayTrianglePre& pre, const float c[3], float r, float tmin, float tmax,
                          TriangleHit* hit) {
    if (!(r > 0.0f) || !std::isfinite(r)) return false;
    const double fx = double(pre.origin.x) - c[0], fy = double(pre.origin.y) - c[1], fz = double(pre.origin.z) - c[2];
    const double dx = pre.direction.x, dy = pre.direction.y, dz = pre.direction.z;
    const double a = dx * dx + dy * dy + dz * dz;
    const double b = -(fx * dx + fy * dy + fz * dz);  // half of the textbook's -b
    // The closest point of the ray's line to the centre, relative to it: f + (b / a) d.
    const double s = b / a;
    const double lx = fx + s * dx, ly = fy + s * dy, lz = fz + s * dz;
    const double rr = double(r) * double(r);
    const double disc = rr - (lx * lx + ly * ly + lz * lz);  // (discriminant / 4) / a
    if (!(disc >= 0.0)) return false;
    const double q = b + std::copysign(std::sqrt(a * disc), b);
    const double cc = fx * fx + fy * fy + fz * fz - rr;
    // The two crossings, nearer first. q is 0 only when both b and the root are: a tangent ray
    // at its closest approach, whose one crossing is t = s = 0.
    double t0 = q != 0.0 ? cc / q : 0.0, t1 = q != 0.0 ? q / a : 0.0;
    if (t0 > t1) std::swap(t0, t1);
    float t = float(t0);
    if (!(t > tmin && t <= tmax)) {
        t = float(t1);
        if (!(t > tmin && t <= tmax)) return false;
    }
    const double nx = (fx + double(t) * dx) / r, ny = (fy + double(t) * dy) / r, nz = (fz + double(t) * dz) / r;
    hit->t = t;
    sphere_uv(nx, ny, nz, &hit->u, &hit->v);
    return true;
}

}  // namespace detail
}  // namespace rtsim
