#pragma once
// Rays, hits and per-ray work counts: the records a trace carries (see docs/trace_format.md).
#include <cstdint>
#include <limits>

#include <glm/glm.hpp>

#include "traces/common/work_counts.h"

namespace rtsim {

using Vec3 = glm::vec3;

/// What a ray is for. Values are stored in traces; never renumber.
enum class RayKind : uint8_t {
    primary = 0,
    shadow = 1,      ///< occlusion (any-hit) ray towards a light
    reflection = 2,  ///< mirror ray from a metallic or smooth surface
    diffuse = 3,     ///< cosine-weighted bounce
    refraction = 4,  ///< transmitted ray through a transmissive material
};
constexpr int kRayKindCount = 5;
const char* ray_kind_name(RayKind kind);
/// Parses "primary", "shadow", ...; throws rtsim::Error naming the text otherwise.
RayKind parse_ray_kind(const char* text);

/// Closest hit (the nearest surface) or any hit (occlusion: stop at the first accepted hit).
enum class TraversalMode : uint8_t { closest_hit = 0, any_hit = 1 };

/// A ray as traced: the segment origin + t * direction for t in [tmin, tmax].
/// The direction is not required to be normalised.
struct Ray {
    Vec3 origin{0.0f};
    float tmin = 0.0f;
    Vec3 direction{0.0f, 0.0f, 1.0f};
    float tmax = std::numeric_limits<float>::infinity();
};

/// Closest (or any) hit of a ray. prim is the stable primitive id (Scene docs), -1 for a miss.
struct Hit {
    int32_t prim = -1;
    int32_t inst = -1;  ///< instance (glTF node / EXT_mesh_gpu_instancing entry) of the hit
    float t = std::numeric_limits<float>::infinity();
    float u = 0.0f;  ///< barycentric weight of vertex 1
    float v = 0.0f;  ///< barycentric weight of vertex 2
    bool valid() const { return prim >= 0; }
};

/// True when a ray may be traversed: finite origin and direction, non-zero direction,
/// tmin <= tmax, tmin not NaN. Rays failing this are rejected, counted and reported.
bool ray_is_valid(const Ray& ray);

}  // namespace rtsim
