#pragma once
// The ray/triangle arithmetic itself, inline so the traversal's hot loop can inline it;
// ray_triangle.cpp exposes the same code as intersect_triangle() (one arithmetic, docs/architecture.md, rule 1).
// Woop, Benthin & Wald 2013, "Watertight Ray/Triangle Intersection", JCGT 2(1), Listing 1,
// without backface culling. Conventions are in docs/intersection.md; the comments below name
// the paper's steps.
#include <cmath>

#include "traces/isect/ray_triangle.h"

namespace rtsim {
namespace detail {

/// True if the triangle's vertices are exactly collinear (or repeated). Only called on the rare
/// candidate-hit path. Float differences are exact in double for vertices whose exponents differ
/// by less than 29, and products of such differences are exact too, so a zero cross product here
/// means exactly zero area. Rounding in the shear can give a collinear triangle a sliver of
/// non-zero area in ray space; this check keeps such triangles from ever being hit.
bool is_degenerate(const float v0[3], const float v1[3], const float v2[3]);

inline bool triangle_kernel(const RayTrianglePre& pre, const float v0[3], const float v1[3],
                            const float v2[3], float tmin, float tmax, TriangleHit* hit) {
    const int kx = pre.kx, ky = pre.ky, kz = pre.kz;
    const float* org = &pre.origin.x;
    // Vertices relative to the ray origin (A = v0, B = v1, C = v2 in the paper).
    const float a_x = v0[kx] - org[kx], a_y = v0[ky] - org[ky];
    const float a_z = v0[kz] - org[kz];
    const float b_x = v1[kx] - org[kx], b_y = v1[ky] - org[ky];
    const float b_z = v1[kz] - org[kz];
    const float c_x = v2[kx] - org[kx], c_y = v2[ky] - org[ky];
    const float c_z = v2[kz] - org[kz];

    // Shear (and later scale) into ray space, where the ray is the +z axis through (0, 0).
    const float ax = a_x - pre.sx * a_z, ay = a_y - pre.sy * a_z;
    const float bx = b_x - pre.sx * b_z, by = b_y - pre.sy * b_z;
    const float cx = c_x - pre.sx * c_z, cy = c_y - pre.sy * c_z;

    // Scaled barycentrics: U weighs A (v0), V weighs B (v1), W weighs C (v2).
    float u = cx * by - cy * bx;
    float v = ax * cy - ay * cx;
    float w = bx * ay - by * ax;

    // An edge function exactly 0 may be a rounding artefact on a shared edge: re-evaluate all
    // three in double (products of floats are exact in double), then round once to float.
    if (__builtin_expect(u == 0.0f || v == 0.0f || w == 0.0f, 0)) {
        u = float(double(cx) * double(by) - double(cy) * double(bx));
        v = float(double(ax) * double(cy) - double(ay) * double(cx));
        w = float(double(bx) * double(ay) - double(by) * double(ax));
    }

    // Edge test without backface culling: the origin is inside if U, V, W share a sign.
    // (Evaluated without short-circuit branches: one unpredictable branch instead of several.)
    const bool any_neg = (u < 0.0f) | (v < 0.0f) | (w < 0.0f);
    const bool any_pos = (u > 0.0f) | (v > 0.0f) | (w > 0.0f);
    if (any_neg & any_pos) return false;
    const float det = u + v + w;
    if (det == 0.0f) return false;

    // Scaled hit distance; compare tmin*det < T <= tmax*det with the sign of det folded in, so
    // no division is spent on rejected triangles. tmin is excluded (as in pbrt): a ray never hits
    // the surface its origin lies on at t = tmin = 0, even where the origin offset is zero.
    const float az = pre.sz * a_z, bz = pre.sz * b_z, cz = pre.sz * c_z;
    const float t_scaled = u * az + v * bz + w * cz;
    const float sign_t = det < 0.0f ? -t_scaled : t_scaled;
    const float abs_det = std::fabs(det);
    if (!(sign_t > tmin * abs_det) | !(sign_t <= tmax * abs_det)) return false;

    // Normalise. The division can round t across an interval end, so check it once more: the
    // returned t is always inside (tmin, tmax].
    const float t = t_scaled / det;
    if (!(t > tmin && t <= tmax)) return false;
    if (is_degenerate(v0, v1, v2)) return false;
    hit->t = t;
    hit->u = v / det;
    hit->v = w / det;
    return true;
}

}  // namespace detail
}  // namespace rtsim
