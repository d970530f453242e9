#pragma once
// What a hit's shader reads (docs/shading.md, "Level of detail"): one arithmetic, called by the
// reference tracer to write a trace's texel addresses and by the shader model to issue its
// texture fetches, so the two are compared like node fetches.
//
// Level of detail: ray cones (Akenine-Moller et al., "Texture Level of Detail Strategies for
// Real-Time Ray Tracing", Ray Tracing Gems 2019, ch. 20; and RTG II 2021, ch. 7). A primary ray's
// cone starts at width 0 with the pixel's spread angle atan(2 tan(fov/2) / height); at a hit the
// width grows by spread x distance; a child starts with its parent's width at the hit, keeping
// the spread (reflection, refraction: flat triangles have no curvature term) or widening it by
// kDiffuseSpread (diffuse bounces, an assumption: a rough lobe of 0.1 rad). The level is
// lambda = Delta_0 + log2|width| - log2|n.d| + 0.5 log2(w h), sampled bilinearly (4 texels,
// REPEAT wrap) at round(lambda) clamped to the chain; every texture the material has is sampled
// once per closest hit of a path ray (shadow rays and misses sample none).
#include <cstdint>
#include <vector>

#include "traces/common/ray.h"
#include "traces/format/shading_format.h"

namespace rtsim {

struct RayCone {
    float width = 0.0f;   ///< world units at the ray's origin
    float spread = 0.0f;  ///< radians
};
constexpr float kDiffuseSpread = 0.1f;

/// The cone of a primary ray through a pinhole camera of vertical field of view `yfov` (radians).
RayCone primary_cone(float yfov, uint32_t height);
/// The cone of a child of kind `kind` of a ray with cone `parent` and direction `dir` hit at `t`.
RayCone child_cone(const RayCone& parent, const Vec3& dir, float t, RayKind kind);

/// True when a ray's hit runs a hit shader that samples textures: a path ray's closest hit.
inline bool shades_hit(bool any_hit, const Hit& hit) { return !any_hit && hit.valid(); }

/// Mip level lambda selects for the hit (before rounding), per Akenine-Moller et al. 2019 eq. 34.
float ray_cone_lod(const TriShadeRecord& tri, const TextureRecord& tex, const Vec3& dir, float t, const RayCone& cone);

/// Address of texel (x, y) of level `level`: levels one after another, 4x4-texel tiles in row
/// order, texels row by row within a tile.
uint64_t texel_address(const TextureRecord& tex, uint32_t level, uint32_t x, uint32_t y);

/// Appends the texel addresses the hit's shader reads (kTexelsPerSample per sample, textures in
/// slot order) and returns the number of samples. `tri` is the primitive's record, `hit` its hit.
uint32_t hit_texels(const std::vector<MaterialRecord>& materials, const std::vector<TextureRecord>& textures,
                    const TriShadeRecord& tri, const Hit& hit, const Vec3& dir, const RayCone& cone,
                    std::vector<uint64_t>* out);

}  // namespace rtsim
