// Ray cones, mip selection and texel addresses (texels.h).
#include "traces/shading/texels.h"

#include <algorithm>
#include <cmath>

namespace rtsim {

RayCone primary_cone(float yfov, uint32_t height) {
    return {0.0f, std::atan(2.0f * std::tan(0.5f * yfov) / float(std::max(1u, height)))};
}

RayCone child_cone(const RayCone& parent, const Vec3& dir, float t, RayKind kind) {
    RayCone c;
    c.width = parent.width + parent.spread * t * glm::length(dir);
    c.spread = parent.spread + (kind == RayKind::diffuse ? kDiffuseSpread : 0.0f);
    return c;
}

float ray_cone_lod(const TriShadeRecord& tri, const TextureRecord& tex, const Vec3& dir, float t, const RayCone& cone) {
    const float len = glm::length(dir);
    const float width = std::abs(cone.width + cone.spread * t * len);
    // A sphere's record has no normal (materials.cpp): its cosine is the mean over the disc a
    // ray sees, 2/3.
    const bool sphere = tri.normal[0] == 0.0f && tri.normal[1] == 0.0f && tri.normal[2] == 0.0f;
    const float cosine =
        sphere ? 2.0f / 3.0f : std::abs(tri.normal[0] * dir.x + tri.normal[1] * dir.y + tri.normal[2] * dir.z) / len;
    if (!(width > 0.0f) || !(cosine > 0.0f)) return 0.0f;
    return tri.lod_base + std::log2(width) - std::log2(cosine) + 0.5f * std::log2(float(tex.width) * float(tex.height));
}

uint64_t texel_address(const TextureRecord& tex, uint32_t level, uint32_t x, uint32_t y) {
    uint64_t offset = 0;
    for (uint32_t k = 0; k < level; ++k) {
        const uint64_t lw = std::max(1u, tex.width >> k), lh = std::max(1u, tex.height >> k);
        offset += ((lw + 3) / 4) * ((lh + 3) / 4) * 16 * tex.bytes_per_texel;
    }
    const uint64_t tiles_x = (std::max(1u, tex.width >> level) + 3) / 4;
    const uint64_t tile = uint64_t(y / 4) * tiles_x + x / 4;
    return tex.base + offset + (tile * 16 + (y % 4) * 4 + x % 4) * tex.bytes_per_texel;
}

namespace {

/// Texel index of coordinate `s` (in texels, REPEAT wrap) and its neighbour.
void wrap_pair(float s, uint32_t size, uint32_t* a, uint32_t* b) {
    const double f = std::floor(double(s) - 0.5);
    const double m = std::fmod(f, double(size));
    const uint32_t i = uint32_t(m < 0.0 ? m + size : m) % size;
    *a = i;
    *b = (i + 1) % size;
}

}  // namespace

uint32_t hit_texels(const std::vector<MaterialRecord>& materials, const std::vector<TextureRecord>& textures,
                    const TriShadeRecord& tri, const Hit& hit, const Vec3& dir, const RayCone& cone,
                    std::vector<uint64_t>* out) {
    if (tri.material >= materials.size()) return 0;
    const MaterialRecord& m = materials[tri.material];
    const float b0 = 1.0f - hit.u - hit.v;
    const float u = b0 * tri.uv[0] + hit.u * tri.uv[2] + hit.v * tri.uv[4];
    const float v = b0 * tri.uv[1] + hit.u * tri.uv[3] + hit.v * tri.uv[5];
    uint32_t samples = 0;
    for (int s = 0; s < kMaterialTextureSlots; ++s) {
        if (m.texture[s] < 0 || size_t(m.texture[s]) >= textures.size()) continue;
        const TextureRecord& tex = textures[size_t(m.texture[s])];
        const float lambda = ray_cone_lod(tri, tex, dir, hit.t, cone);
        const float rounded = std::isfinite(lambda) ? std::nearbyint(lambda) : 0.0f;
        const uint32_t level = uint32_t(std::clamp(rounded, 0.0f, float(tex.mips - 1)));
        const uint32_t lw = std::max(1u, tex.width >> level), lh = std::max(1u, tex.height >> level);
        const float su = std::isfinite(u) ? u * float(lw) : 0.0f, sv = std::isfinite(v) ? v * float(lh) : 0.0f;
        uint32_t x0, x1, y0, y1;
        wrap_pair(su, lw, &x0, &x1);
        wrap_pair(sv, lh, &y0, &y1);
        out->push_back(texel_address(tex, level, x0, y0));
        out->push_back(texel_address(tex, level, x1, y0));
        out->push_back(texel_address(tex, level, x0, y1));
        out->push_back(texel_address(tex, level, x1, y1));
        ++samples;
    }
    return samples;
}

}  // namespace rtsim
