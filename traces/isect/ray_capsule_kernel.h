#pragma once
// Ray/capsule intersection (a sphere of radius r swept along the segment p0-p1: a cylinder with
// hemispherical caps; hair strands and fibres as chains of capsules), inline for the traversal's
// hot loop (docs/intersection.md, "Ray/capsule"). The capsule's surface is the union of three
// pieces: the cylinder's crossings whose axial coordinate lies on the segment, and each end
// sphere's crossings beyond its end. Every piece's two crossings are computed as the sphere's are
// (Haines et al. 2019: the discriminant from the closest approach, the roots without
// cancellation), in double from float inputs, and the nearest crossing inside (tmin, tmax] is
// the hit, so rays from inside and the far side of an alpha-cut capsule come out as a sphere's.
#include <cmath>
#include <utility>

#include "traces/isect/ray_sphere_kernel.h"

namespace rtsim {
namespace detail {

/// Texture coordinates of a capsule hit: u along the axis (0 at p0, 1 at p1; the caps at the
/// ends), v the angle about the axis over 2 pi, from a frame fixed by the axis alone.
inline void capsule_uv(const Dvec& axis, double length, const Dvec& rel, float* u, float* v) {
    constexpr double kPi = 3.14159265358979323846;
    const double y = dot(rel, axis);
    const double along = length > 0.0 ? y / length : 0.0;
    *u = float(along < 0.0 ? 0.0 : (along > 1.0 ? 1.0 : along));
    // A frame across the axis: e1 from the axis and the world axis it is least aligned with.
    const Dvec w = std::fabs(axis.x) <= std::fabs(axis.y) && std::fabs(axis.x) <= std::fabs(axis.z)
                       ? Dvec{1, 0, 0}
                       : (std::fabs(axis.y) <= std::fabs(axis.z) ? Dvec{0, 1, 0} : Dvec{0, 0, 1});
    const Dvec e1 = mad(w, -dot(w, axis), axis);
    const Dvec e2{axis.y * e1.z - axis.z * e1.y, axis.z * e1.x - axis.x * e1.z, axis.x * e1.y - axis.y * e1.x};
    double phi = std::atan2(dot(rel, e2), dot(rel, e1));
    if (phi < 0.0) phi += 2.0 * kPi;
    *v = float(phi / (2.0 * kPi));
    if (!(*v < 1.0f)) *v = 0.0f;
}

/// True if the ray hits the capsule (axis p0-p1, radius r) at tmin < t <= tmax: the nearest
/// crossing of its surface in the interval. A capsule of zero length is its end sphere; a
/// radius that is 0, negative or not finite is never hit.
inline bool capsule_kernel(const RayTrianglePre& pre, const float p0[3], const float p1[3], float r, float tmin,
                           float tmax, TriangleHit* hit) {
    if (!(r > 0.0f) || !std::isfinite(r)) return false;
    const Dvec o{pre.origin.x, pre.origin.y, pre.origin.z}, d{pre.direction.x, pre.direction.y, pre.direction.z};
    const Dvec a{p0[0], p0[1], p0[2]}, b{p1[0], p1[1], p1[2]};
    const Dvec ba = sub(b, a);
    const double length = std::sqrt(dot(ba, ba));
    const Dvec axis = length > 0.0 ? Dvec{ba.x / length, ba.y / length, ba.z / length} : Dvec{0, 0, 1};
    const double rr = double(r) * double(r);
    const Dvec fa = sub(o, a), fb = sub(o, b);
    // The nearest crossing so far, as the float it is reported in.
    bool found = false;
    float best = 0.0f;
    auto offer = [&](double t) {
        const float tf = float(t);
        if (tf > tmin && tf <= tmax && (!found || tf < best)) found = true, best = tf;
    };
    double t0, t1;
    // The cylinder across the axis, where the crossing's axial coordinate is on the segment.
    if (length > 0.0) {
        const Dvec fp = mad(fa, -dot(fa, axis), axis), dp = mad(d, -dot(d, axis), axis);
        if (quadric_roots(fp, dp, rr, &t0, &t1)) {
            for (double t : {t0, t1}) {
                const double y = dot(fa, axis) + t * dot(d, axis);
                if (y >= 0.0 && y <= length) offer(t);
            }
        }
    }
    // The end spheres, beyond their ends.
    if (quadric_roots(fa, d, rr, &t0, &t1))
        for (double t : {t0, t1})
            if (length == 0.0 || dot(fa, axis) + t * dot(d, axis) <= 0.0) offer(t);
    if (length > 0.0 && quadric_roots(fb, d, rr, &t0, &t1))
        for (double t : {t0, t1})
            if (dot(fb, axis) + t * dot(d, axis) >= 0.0) offer(t);
    if (!found) return false;
    hit->t = best;
    capsule_uv(axis, length, mad(fa, double(best), d), &hit->u, &hit->v);
    return true;
}

}  // namespace detail
}  // namespace rtsim
