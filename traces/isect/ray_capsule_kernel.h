#pragma once
// Ray/capsule intersection: a linear swept sphere, a sphere swept along the segment p0-p1 with
// its radius going linearly from r0 to r1 (hair strands and fibres as chains of them; recent RT
// cores test them natively), inline for the traversal's hot loop (docs/intersection.md,
// "Ray/capsule"). The surface is the union of three pieces: the body (with equal radii a
// cylinder; with two radii the cone that touches both end spheres, as Embree's round linear
// curves take it), whose crossings count where they lie between the two circles of contact, and
// each end sphere's crossings beyond its circle. The sphere's and cylinder's two crossings are
// computed as Haines et al. 2019 do (the discriminant from the closest approach, the roots
// without cancellation); the cone's from its quadric with the ray's origin moved first to its
// closest point to the segment's midpoint (no cancellation from a distant origin). All in double
// from float inputs, and the nearest crossing inside (tmin, tmax] is the hit, so rays from
// inside and the far side of an alpha-cut capsule come out as a sphere's.
#include <cmath>
#include <utility>

#include "traces/common/round_cone.h"
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

/// The nearest crossing so far, as the float it is reported in.
struct NearestCrossing {
    float tmin, tmax;
    bool found = false;
    float best = 0.0f;
    void offer(double t) {
        const float tf = float(t);
        if (tf > tmin && tf <= tmax && (!found || tf < best)) found = true, best = tf;
    }
};

/// The crossings of a capsule of one radius r: the cylinder's where their axial coordinate is on
/// the segment, each end sphere's beyond its end (a capsule of zero length is its sphere).
inline void capsule_crossings(const Dvec& fa, const Dvec& fb, const Dvec& d, const Dvec& axis, double length,
                              double r, NearestCrossing* near) {
    const double rr = r * r;
    double t0, t1;
    if (length > 0.0) {
        const Dvec fp = mad(fa, -dot(fa, axis), axis), dp = mad(d, -dot(d, axis), axis);
        if (quadric_roots(fp, dp, rr, &t0, &t1)) {
            for (double t : {t0, t1}) {
                const double y = dot(fa, axis) + t * dot(d, axis);
                if (y >= 0.0 && y <= length) near->offer(t);
            }
        }
    }
    if (quadric_roots(fa, d, rr, &t0, &t1))
        for (double t : {t0, t1})
            if (length == 0.0 || dot(fa, axis) + t * dot(d, axis) <= 0.0) near->offer(t);
    if (length > 0.0 && quadric_roots(fb, d, rr, &t0, &t1))
        for (double t : {t0, t1})
            if (dot(fb, axis) + t * dot(d, axis) >= 0.0) near->offer(t);
}

/// The crossings of a round cone (radii r0 at p0 and r1 at p1, |r1 - r0| < length), for the ray
/// shift + t d with fa, fb its origin relative to the ends. With k = (r1 - r0) / length and
/// c2 = 1 - k^2, the sphere of centre p0 + s axis and radius r0 + k s touches the envelope where
/// the normal n has n.axis = -k; so the body is the cone q^2 c2 = (r0 + k y)^2 (q the distance
/// from the axis, y the axial coordinate), between its circles of contact at y = -k r0 and
/// y = length c2 - k r1 (where the cone's radius is positive), and the spheres' caps lie beyond them.
inline void round_cone_crossings(const Dvec& fa, const Dvec& fb, const Dvec& d, const Dvec& axis, double length,
                                 double r0, double r1, double shift, NearestCrossing* near) {
    const double k = (r1 - r0) / length, c2 = 1.0 - k * k;
    const double fy = dot(fa, axis), dy = dot(d, axis);
    const Dvec fp = mad(fa, -fy, axis), dp = mad(d, -dy, axis);
    const double g = r0 + k * fy;  // the cone's radius x c at the origin's axial coordinate
    const double qa = c2 * dot(dp, dp) - k * k * dy * dy, qb = c2 * dot(fp, dp) - k * dy * g,
                 qc = c2 * dot(fp, fp) - g * g;
    double roots[2];
    int n = 0;
    const double disc = qb * qb - qa * qc;
    if (disc >= 0.0) {
        const double q = -(qb + std::copysign(std::sqrt(disc), qb));
        if (qa != 0.0 && q != 0.0) roots[n++] = q / qa, roots[n++] = qc / q;
        else if (qb != 0.0) roots[n++] = -qc / (2.0 * qb);  // a ray parallel to one of the cone's lines
    }
    for (int i = 0; i < n; ++i) {
        const double y = fy + roots[i] * dy;
        if (y >= -k * r0 && y <= length - k * r1) near->offer(shift + roots[i]);
    }
    double t0, t1;
    if (quadric_roots(fa, d, r0 * r0, &t0, &t1))
        for (double t : {t0, t1})
            if (fy + t * dy <= -k * r0) near->offer(shift + t);
    if (quadric_roots(fb, d, r1 * r1, &t0, &t1))
        for (double t : {t0, t1})
            if (dot(fb, axis) + t * dy >= -k * r1) near->offer(shift + t);
}

/// True if the ray hits the capsule (axis p0-p1, radii r0 at p0 and r1 at p1) at tmin < t <=
/// tmax: the nearest crossing of its surface in the interval. A capsule of zero length, or whose
/// larger end sphere holds the smaller (|r1 - r0| >= length), is that sphere; a capsule whose
/// larger radius is 0, negative or not finite is never hit, and a negative radius counts as 0.
inline bool capsule_kernel(const RayTrianglePre& pre, const float p0[3], const float p1[3], float r0, float r1,
                           float tmin, float tmax, TriangleHit* hit) {
    const float rmax = r0 > r1 ? r0 : r1;
    if (!(rmax > 0.0f) || !std::isfinite(rmax)) return false;
    const Dvec d{pre.direction.x, pre.direction.y, pre.direction.z};
    Dvec o{pre.origin.x, pre.origin.y, pre.origin.z}, a{p0[0], p0[1], p0[2]}, b{p1[0], p1[1], p1[2]};
    Dvec ba = sub(b, a);
    double length = std::sqrt(dot(ba, ba));
    const double ra = r0 > 0.0f ? r0 : 0.0, rb = r1 > 0.0f ? r1 : 0.0;
    NearestCrossing near{tmin, tmax};
    Dvec fa = sub(o, a);
    Dvec axis = length > 0.0 ? Dvec{ba.x / length, ba.y / length, ba.z / length} : Dvec{0, 0, 1};
    if (ra == rb) {
        capsule_crossings(fa, sub(o, b), d, axis, length, ra, &near);
    } else if (end_sphere_holds_other(length, ra, rb)) {
        if (rb > ra) a = b, fa = sub(o, a);
        length = 0.0;
        capsule_crossings(fa, fa, d, axis, 0.0, rmax, &near);
    } else {
        const Dvec mid = mad(a, 0.5, ba);
        const double dl = dot(d, d);
        const double shift = dl > 0.0 ? dot(sub(mid, o), d) / dl : 0.0;
        const Dvec os = mad(o, shift, d);
        round_cone_crossings(sub(os, a), sub(os, b), d, axis, length, ra, rb, shift, &near);
    }
    if (!near.found) return false;
    hit->t = near.best;
    capsule_uv(axis, length, mad(fa, double(near.best), d), &hit->u, &hit->v);
    return true;
}

}  // namespace detail
}  // namespace rtsim
