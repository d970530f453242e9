#pragma once
// Watertight ray/triangle intersection (Woop, Benthin & Wald 2013, JCGT 2(1)): shear and scale
// the triangle into ray space, edge functions in float with a double-precision re-evaluation when
// one is exactly zero. Rays through shared edges and vertices of closed meshes never escape.
// Degenerate (zero-area) triangles are never hit and never produce NaN.
#include "traces/common/ray.h"

namespace rtsim {

struct RayTrianglePre {
    int kx = 0, ky = 1, kz = 2;  ///< axis permutation: kz is the largest |direction| component
    float sx = 0, sy = 0, sz = 1;  ///< shear constants
    Vec3 origin;
    Vec3 direction;  ///< the ray's own direction (curved primitives test in world space)
};

RayTrianglePre ray_triangle_precompute(const Ray& ray);

struct TriangleHit {
    float t, u, v;
};

/// True if the ray hits the triangle at a distance tmin < t <= tmax: tmin is excluded, so a ray
/// starting on a surface (tmin = 0) does not hit it at t = 0 (the pbrt convention).
bool intersect_triangle(const RayTrianglePre& pre, const float v0[3], const float v1[3],
                        const float v2[3], float tmin, float tmax, TriangleHit* hit);

}  // namespace rtsim
