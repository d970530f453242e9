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

struct Dvec {
    double x, y, z;
};
inline double dot(const Dvec& a, const Dvec& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Dvec sub(const Dvec& a, const Dvec& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Dvec mad(const Dvec& a, double s, const Dvec& b) { return {a.x + s * b.x, a.y + s * b.y, a.z + s * b.z}; }

/// The two crossings (nearer first) of the ray f + t d (f: origin relative to a point of the
/// shape) with the quadric |f + t d|^2 = rr, where f and d are already projected as the shape
/// needs (the whole vectors for a sphere, their parts across the axis for a cylinder). False
/// when the ray misses (or d is 0).
inline bool quadric_roots(const Dvec& f, const Dvec& d, double rr, double* t0, double* t1) {
    const double a = dot(d, d);
    if (!(a > 0.0)) return false;
    const double b = -dot(f, d);
    const Dvec l = mad(f, b / a, d);
    const double disc = rr - dot(l, l);
    if (!(disc >= 0.0)) return false;
    const double q = b + std::copysign(std::sqrt(a * disc), b);
    const double c = dot(f, f) - rr;
    *t0 = q != 0.0 ? c / q : 0.0;
    *t1 = q != 0.0 ? q / a : 0.0;
    if (*t0 > *t1) std::swap(*t0, *t1);
    return true;
}

/// True if the ray hits the sphere (centre c, radius r) at tmin < t <= tmax: the nearer of the
/// two crossings inside the interval (the far one for a ray starting inside). A tangent ray hits
/// at its one point of contact; a sphere of radius 0 (or not finite) is never hit. hit->u, v are
/// the hit point's sphere coordinates (sphere_uv).
inline bool sphere_kernel(const RayTrianglePre& pre, const float c[3], float r, float tmin, float tmax,
                          TriangleHit* hit) {
    if (!(r > 0.0f) || !std::isfinite(r)) return false;
    const Dvec f{double(pre.origin.x) - c[0], double(pre.origin.y) - c[1], double(pre.origin.z) - c[2]};
    const Dvec d{pre.direction.x, pre.direction.y, pre.direction.z};
    double t0, t1;
    if (!quadric_roots(f, d, double(r) * double(r), &t0, &t1)) return false;
    float t = float(t0);
    if (!(t > tmin && t <= tmax)) {
        t = float(t1);
        if (!(t > tmin && t <= tmax)) return false;
    }
    const Dvec n = mad(f, double(t), d);
    hit->t = t;
    sphere_uv(n.x / r, n.y / r, n.z / r, &hit->u, &hit->v);
    return true;
}

}  // namespace detail
}  // namespace rtsim
