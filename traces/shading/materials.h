#pragma once
// What a scene's materials ask of a shader (docs/shading.md, "Materials and textures"): each
// material's features (from glTF: its textures, alpha mode, transmission, metallic, emissive), a
// hit shader per distinct feature set, and its textures as regions of the memory image with full
// mip chains. Images a glTF carries are taken at their size; textures the shared scenes had
// stripped get stand-ins by the rule below; the built-in Cornell box has procedural textures.
//
// Stand-in rule (a realistic footprint for scenes whose images were removed):
//   * extras.strippedTextures lists the slots: one stand-in per listed slot;
//   * extras.factorsBakedFromKhronosTextureMeans (Sponza): base colour and normal map (every
//     Khronos Sponza material has both);
//   * base colour and normal: 1024 x 1024 RGBA8; metallic-roughness, emissive, occlusion: 512 x 512.
// Every texture is RGBA8 with its full mip chain down to 1 x 1 (4/3 of level 0).
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "traces/format/shading_format.h"
#include "traces/scene/scene.h"

namespace rtsim {

/// A material's features, as bits of MaterialRecord::features.
enum ShaderFeature : uint32_t {
    kFeatureBaseColorTex = 1u << 0,
    kFeatureNormalTex = 1u << 1,
    kFeatureMetalRoughTex = 1u << 2,
    kFeatureEmissiveTex = 1u << 3,
    kFeatureOcclusionTex = 1u << 4,
    kFeatureAlphaMask = 1u << 5,
    kFeatureAlphaBlend = 1u << 6,
    kFeatureTransmission = 1u << 7,
    kFeatureMetallic = 1u << 8,  ///< reflects (metallic >= 0.5 or roughness <= 0.2)
    kFeatureEmissive = 1u << 9,
};
constexpr int kShaderFeatureCount = 10;
/// "base_color_tex", "normal_tex", ...: names of the bits, in order (stats and docs).
const char* shader_feature_name(int bit);

enum class TextureOrigin : uint8_t { image = 0, stand_in = 1, procedural = 2 };
const char* texture_origin_name(TextureOrigin o);

/// Textures are laid out from 1 TiB up, each chain 4 KiB aligned: above the acceleration-structure
/// image and every region the model adds (rays, hits, stacks: each from a 4 GiB granule past the
/// image), so a trace's textures leave the model's own addresses where a trace without them has
/// them and the RT unit's figures do not move with them.
constexpr uint64_t kTextureBase = uint64_t(1) << 40;
constexpr uint64_t kTextureAlign = 4096;

/// The shading side of a scene: materials, their textures at addresses, and per primitive its
/// texture coordinates and LOD constant.
struct ShadingScene {
    std::vector<MaterialRecord> materials;
    std::vector<TextureRecord> textures;
    std::vector<std::string> shader_names;  ///< per shader id: its features joined by '+'
    uint64_t texture_base = 0, texture_end = 0;  ///< [base, end): the textures' address range
    uint32_t shaders = 0;

    bool has_textures() const { return !textures.empty(); }
    /// The manifest's "shading": materials (features, shader, textures), textures (size, mips,
    /// bytes, address, origin), the rule applied and the total footprint.
    nlohmann::json to_json(const Scene& scene) const;
};

/// Materials and textures of `scene` (`procedural`: a built-in scene named `name`), textures
/// placed from kTextureBase (`image_end`, AccelImage::end_address(), must lie below it).
ShadingScene build_shading_scene(const Scene& scene, const std::string& name, bool procedural, uint64_t image_end);

/// Primitive `prim`'s shading record: TEXCOORD_0 of its corners, else the planar projection (the
/// world coordinates of the two axes other than the normal's largest, one texture repeat per
/// world unit), its material, the LOD constant and the unit normal.
TriShadeRecord tri_shade_record(const Scene& scene, uint32_t prim);

}  // namespace rtsim
