#pragma once
// Surface points of hits and robust spawning of secondary rays from them.
#include <cstdint>

#include "traces/common/ray.h"
#include "traces/scene/scene.h"

namespace rtsim {

/// A hit turned into geometry: position with a conservative rounding-error bound, and the
/// geometric normal flipped to face the incoming ray.
struct SurfacePoint {
    Vec3 position;
    Vec3 error;   ///< per-component absolute error bound of position
    Vec3 normal;  ///< unit, facing the side the ray came from
    bool front = true;  ///< the ray hit the front (counter-clockwise) side: entering a solid
    uint32_t prim = 0;
    uint32_t material = 0;
};

SurfacePoint surface_point(const Scene& scene, const Ray& ray, const Hit& hit);

/// Origin for a ray leaving p towards direction w: p pushed along the normal past its error
/// bound and rounded away from the surface (pbrt-v4 OffsetRayOrigin, Pharr et al. 2023, 6.8.6),
/// so the new ray can never re-hit the surface it starts on.
Vec3 offset_ray_origin(const SurfacePoint& p, const Vec3& w);

/// Orthonormal basis around a unit normal (Duff et al. 2017, "Building an orthonormal basis,
/// revisited").
void make_basis(const Vec3& n, Vec3* b1, Vec3* b2);

/// Cosine-weighted direction in the hemisphere around n (Malley's method), from u1, u2 in [0,1).
Vec3 cosine_hemisphere(const Vec3& n, float u1, float u2);

/// Mirror reflection of incoming direction d about unit normal n.
Vec3 reflect(const Vec3& d, const Vec3& n);

/// Glossy reflection of unit incoming direction d off a surface of unit normal n (facing d's
/// origin) with GGX roughness `alpha` (glTF: roughness squared): a microfacet normal sampled
/// from the distribution of normals visible from -d (Heitz 2018, "Sampling the GGX Distribution
/// of Visible Normals", JCGT 7(4)) from u1, u2 in [0,1), and d reflected about it. Returns false
/// when the reflected direction points into the surface (the path is absorbed there).
bool ggx_reflect(const Vec3& d, const Vec3& n, float alpha, float u1, float u2, Vec3* out);

/// Refraction of unit d through a surface with unit normal n facing d's origin side, from a
/// medium of index eta_i into eta_t. Returns false on total internal reflection.
bool refract(const Vec3& d, const Vec3& n, float eta_i, float eta_t, Vec3* out);

}  // namespace rtsim
