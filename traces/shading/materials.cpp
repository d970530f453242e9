// Materials to shaders and textures (the stand-in rule is in materials.h).
#include "traces/shading/materials.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "traces/common/error.h"
#include "traces/raygen/workload.h"

namespace rtsim {

using nlohmann::json;

namespace {

constexpr const char* kFeatureNames[kShaderFeatureCount] = {
    "base_color_tex", "normal_tex", "metal_rough_tex", "emissive_tex", "occlusion_tex",
    "alpha_mask",     "alpha_blend", "transmission",   "metallic",     "emissive"};
constexpr const char* kSlotNames[kMaterialTextureSlots] = {"base_color", "normal", "metallic_roughness",
                                                           "emissive", "occlusion"};

uint64_t align_to(uint64_t x, uint64_t a) { return (x + a - 1) / a * a; }

uint16_t mip_count(uint32_t w, uint32_t h) {
    uint16_t n = 1;
    while (w > 1 || h > 1) {
        w = std::max(1u, w / 2), h = std::max(1u, h / 2);
        ++n;
    }
    return n;
}

/// Bytes of a chain of 4x4-texel tiles (a level smaller than a tile still takes one).
uint64_t chain_bytes(uint32_t w, uint32_t h, uint16_t mips, uint32_t texel_bytes) {
    uint64_t bytes = 0;
    for (uint16_t k = 0; k < mips; ++k) {
        const uint64_t lw = std::max(1u, w >> k), lh = std::max(1u, h >> k);
        bytes += ((lw + 3) / 4) * ((lh + 3) / 4) * 16 * texel_bytes;
    }
    return bytes;
}

/// The stand-in size of a slot (materials.h).
uint32_t stand_in_size(int slot) {
    return slot == int(TextureSlot::base_color) || slot == int(TextureSlot::normal) ? 1024 : 512;
}

/// Slot `s` of material `m`: (size, origin), or size 0 when the material samples no texture there.
struct SlotTexture {
    uint32_t width = 0, height = 0;
    TextureOrigin origin = TextureOrigin::image;
};
SlotTexture slot_texture(const Material& m, int s, const std::string& name, bool procedural) {
    const MaterialTexture& t = m.textures[s];
    if (t.source == MaterialTexture::Source::image && t.width && t.height) return {t.width, t.height, TextureOrigin::image};
    const bool baked = m.textures_baked && (s == int(TextureSlot::base_color) || s == int(TextureSlot::normal));
    if (t.source != MaterialTexture::Source::none || baked)
        return {stand_in_size(s), stand_in_size(s), TextureOrigin::stand_in};
    // The built-in Cornell box: a 512 x 512 checker on each diffuse wall (emitters and the mirror
    // keep their constants), so the main job runs a texture model anywhere.
    if (procedural && name == "cornell" && s == int(TextureSlot::base_color) && !m.is_emissive() &&
        !material_reflects(m))
        return {512, 512, TextureOrigin::procedural};
    return {};
}

uint32_t features_of(const Material& m, const int32_t* texture) {
    uint32_t f = 0;
    for (int s = 0; s < kMaterialTextureSlots; ++s)
        if (texture[s] >= 0) f |= 1u << s;
    if (m.alpha_mode == AlphaMode::mask) f |= kFeatureAlphaMask;
    if (m.alpha_mode == AlphaMode::blend) f |= kFeatureAlphaBlend;
    if (material_refracts(m)) f |= kFeatureTransmission;
    if (material_reflects(m)) f |= kFeatureMetallic;
    if (m.is_emissive()) f |= kFeatureEmissive;
    return f;
}

std::string features_text(uint32_t f) {
    std::string out;
    for (int b = 0; b < kShaderFeatureCount; ++b)
        if (f & (1u << b)) out += (out.empty() ? "" : "+") + std::string(kFeatureNames[b]);
    return out.empty() ? "constant" : out;
}

}  // namespace

const char* shader_feature_name(int bit) { return bit >= 0 && bit < kShaderFeatureCount ? kFeatureNames[bit] : "?"; }

const char* texture_origin_name(TextureOrigin o) {
    switch (o) {
    case TextureOrigin::image: return "image";
    case TextureOrigin::stand_in: return "stand-in";
    case TextureOrigin::procedural: return "procedural";
    }
    return "?";
}

ShadingScene build_shading_scene(const Scene& scene, const std::string& name, bool procedural, uint64_t image_end) {
    ShadingScene out;
    require(image_end < kTextureBase / 2, scene.source + ": the acceleration-structure image ends at " +
                                              std::to_string(image_end) + ", too close to the textures' base");
    out.texture_base = kTextureBase;
    uint64_t next = out.texture_base;
    std::map<uint32_t, uint16_t> shader_of;  // feature set -> dense id, in first-use order
    for (const Material& m : scene.materials) {
        MaterialRecord r{};
        for (int s = 0; s < kMaterialTextureSlots; ++s) {
            r.texture[s] = -1;
            const SlotTexture st = slot_texture(m, s, name, procedural);
            if (!st.width) continue;
            TextureRecord t{};
            t.width = st.width;
            t.height = st.height;
            t.mips = mip_count(st.width, st.height);
            t.bytes_per_texel = 4;
            t.slot = uint8_t(s);
            t.origin = uint8_t(st.origin);
            t.bytes = chain_bytes(t.width, t.height, t.mips, t.bytes_per_texel);
            t.base = next;
            next = align_to(next + t.bytes, kTextureAlign);
            r.texture[s] = int32_t(out.textures.size());
            out.textures.push_back(t);
        }
        r.features = features_of(m, r.texture);
        auto [it, added] = shader_of.emplace(r.features, uint16_t(shader_of.size()));
        if (added) out.shader_names.push_back(features_text(r.features));
        r.shader = it->second;
        r.alpha_cutoff = m.alpha_cutoff;
        out.materials.push_back(r);
    }
    out.shaders = uint32_t(shader_of.size());
    out.texture_end = next;
    return out;
}

json ShadingScene::to_json(const Scene& scene) const {
    json mats = json::array(), texs = json::array();
    uint64_t bytes = 0;
    for (size_t i = 0; i < materials.size(); ++i) {
        json slots = json::object();
        for (int s = 0; s < kMaterialTextureSlots; ++s)
            if (materials[i].texture[s] >= 0) slots[kSlotNames[s]] = materials[i].texture[s];
        mats.push_back({{"name", scene.materials[i].name},
                        {"shader", materials[i].shader},
                        {"features", shader_names[materials[i].shader]},
                        {"textures", slots}});
    }
    std::map<std::string, uint64_t> by_origin;
    for (const TextureRecord& t : textures) {
        const std::string origin = texture_origin_name(TextureOrigin(t.origin));
        texs.push_back({{"slot", kSlotNames[t.slot]},
                        {"size", {t.width, t.height}},
                        {"format", "rgba8"},
                        {"mips", t.mips},
                        {"bytes", t.bytes},
                        {"address", t.base},
                        {"origin", origin}});
        bytes += t.bytes;
        by_origin[origin] += 1;
    }
    return {{"materials", mats},
            {"textures", texs},
            {"shaders", shader_names},
            {"texture_bytes", bytes},
            {"textures_by_origin", by_origin},
            {"texture_model", has_textures() ? "textures sampled by hit shaders (docs/shading.md)"
                                             : "no material samples a texture: no texture model"},
            {"stand_in_rule",
             "slots named by extras.strippedTextures, or base colour and normal for "
             "extras.factorsBakedFromKhronosTextureMeans: 1024x1024 RGBA8 (base colour, normal), "
             "512x512 (others), full mip chains (docs/shading.md)"},
            {"lod_rule", "ray cones (Akenine-Moller et al. 2019), bilinear at the nearest mip level"}};
}

namespace {

/// A curved primitive's record: its texture coordinates are its hit's own (u, v: a sphere's
/// longitude and colatitude, a capsule's axial and angular coordinates), which the barycentric
/// interpolation every shader runs reproduces from these corners; the normal is zero (each hit
/// has its own; the level-of-detail rule then takes a sphere's mean cosine, texels.cpp), and the
/// level of detail spreads the unit uv square over the surface's area.
TriShadeRecord curved_shade_record(const Scene& scene, uint32_t prim) {
    TriShadeRecord r{};
    const float uv[6] = {0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 1.0f};
    for (int i = 0; i < 6; ++i) r.uv[i] = uv[i];
    r.material = scene.material_of(prim);
    r.lod_base = float(0.5 * std::log2(1.0 / curved_area(scene, prim)));
    return r;
}

}  // namespace

TriShadeRecord tri_shade_record(const Scene& scene, uint32_t prim) {
    if (scene.is_curved(prim)) return curved_shade_record(scene, prim);
    TriShadeRecord r{};
    const Triangle t = scene.world_triangle(prim);
    const Vec3 n = glm::cross(t.v1 - t.v0, t.v2 - t.v0);
    const float len = glm::length(n);
    const Vec3 un = len > 0.0f ? n / len : Vec3(0.0f, 0.0f, 1.0f);
    const Instance& inst = scene.instances[scene.instance_of(prim)];
    const Mesh& mesh = scene.meshes[inst.mesh];
    const size_t k = prim - inst.prim_base;
    glm::vec2 uv[3];
    if (!mesh.uvs.empty()) {
        for (int c = 0; c < 3; ++c) uv[c] = mesh.uvs[3 * k + size_t(c)];
    } else {
        // Planar projection onto the plane across the normal's largest axis.
        const Vec3 a = glm::abs(un);
        const int axis = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
        const int i0 = (axis + 1) % 3, i1 = (axis + 2) % 3;
        const Vec3 p[3] = {t.v0, t.v1, t.v2};
        for (int c = 0; c < 3; ++c) uv[c] = glm::vec2(p[c][i0], p[c][i1]);
    }
    for (int c = 0; c < 3; ++c) r.uv[2 * c] = uv[c].x, r.uv[2 * c + 1] = uv[c].y;
    r.material = scene.material_of(prim);
    const glm::vec2 e1 = uv[1] - uv[0], e2 = uv[2] - uv[0];
    const double uv_area = std::abs(double(e1.x) * e2.y - double(e1.y) * e2.x);
    const double world_area = double(len);
    // Degenerate in uv or in space: the finest level (LOD 0) everywhere on it.
    r.lod_base = uv_area > 0.0 && world_area > 0.0 ? float(0.5 * std::log2(uv_area / world_area)) : -64.0f;
    r.normal[0] = un.x, r.normal[1] = un.y, r.normal[2] = un.z;
    return r;
}

}  // namespace rtsim
