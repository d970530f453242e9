#pragma once
// The shading sections of a trace (version 5, docs/trace_format.md "Shading"): what the shader
// model needs and what it is checked against. Written by the reference tracer for every trace;
// a trace of version 3 or 4 has none and is simulated without shading.
//
//   MATL  one MaterialRecord per scene material: its shader and the textures it samples
//   TEXR  one TextureRecord per texture: size, format, mip chain, address in the memory image
//   PTRI  one TriShadeRecord per primitive: TEXCOORD_0 of its corners, material, LOD constant
//   SHAD  one ShadeRecord per ray (same index as RAYS): parent, ray cone, reference shading
//   TXFT  texel addresses, ShadeRecord::samples x 4 per ray from ShadeRecord::first_fetch
#include <cstdint>

#include "traces/common/record_layout.h"

namespace rtsim {

constexpr int kMaterialTextureSlots = 5;  ///< base colour, normal, metallic-roughness, emissive, occlusion
constexpr uint32_t kNoMaterial = 0xFFFFFFFFu;
constexpr uint16_t kMissShader = 0xFFFF;
constexpr uint32_t kTexelsPerSample = 4;  ///< bilinear at one mip level

#pragma pack(push, 1)
/// One material (32 bytes).
struct MaterialRecord {
    uint32_t features;                       //  0: ShaderFeature bits (traces/shading/materials.h)
    uint16_t shader;                         //  4: dense id of the feature set (the hit shader)
    uint16_t reserved;                       //  6
    int32_t texture[kMaterialTextureSlots];  //  8: TEXR index per slot, -1 none
    float alpha_cutoff;                      // 28
};
/// One texture (32 bytes): mip level k is (max(1, width >> k) x max(1, height >> k)), levels
/// stored one after the other from `base`, each in 4x4-texel tiles (one 64-byte line of RGBA8).
struct TextureRecord {
    uint64_t base;            //  0: address of level 0 in the memory image
    uint64_t bytes;           //  8: the whole chain
    uint32_t width;           // 16
    uint32_t height;          // 20
    uint16_t mips;            // 24
    uint8_t bytes_per_texel;  // 26: 4 (RGBA8)
    uint8_t slot;             // 27: TextureSlot
    uint8_t origin;           // 28: TextureOrigin (image, stand-in, procedural)
    uint8_t reserved[3];      // 29
};
/// Shading attributes of one primitive (44 bytes).
struct TriShadeRecord {
    float uv[6];        //  0: TEXCOORD_0 of v0, v1, v2 (or the planar projection, see materials.h)
    uint32_t material;  // 24
    float lod_base;     // 28: 0.5 log2(uv area / world area) (Akenine-Moller et al. 2019, Delta_0)
    float normal[3];    // 32: unit geometric normal in world space (the LOD rule's cosine); zero for a sphere
};
/// Shading of one ray (32 bytes).
struct ShadeRecord {
    int64_t parent;        //  0: index of the ray whose shading spawned it, -1 for ray generation
    uint32_t material;     //  8: material of the hit, kNoMaterial for a miss or a shadow ray
    uint16_t shader;       // 12: hit shader, kMissShader for a miss; shadow rays: kMissShader
    uint16_t samples;      // 14: texture samples its shader takes (kTexelsPerSample texels each)
    uint64_t first_fetch;  // 16: its first texel address in TXFT
    float cone_width;      // 24: ray cone width at the origin (world units)
    float cone_spread;     // 28: ray cone spread angle (radians)
};
#pragma pack(pop)
static_assert(sizeof(MaterialRecord) == 32, "MaterialRecord layout");
static_assert(sizeof(TextureRecord) == 32, "TextureRecord layout");
static_assert(sizeof(TriShadeRecord) == 44, "TriShadeRecord layout");
static_assert(sizeof(ShadeRecord) == 32, "ShadeRecord layout");

inline RecordLayout layout_of(const MaterialRecord*) {
    return {RTSIM_FIELD(MaterialRecord, features), RTSIM_FIELD(MaterialRecord, shader),
            RTSIM_FIELD(MaterialRecord, reserved), RTSIM_FIELD(MaterialRecord, texture),
            RTSIM_FIELD(MaterialRecord, alpha_cutoff)};
}
inline RecordLayout layout_of(const TextureRecord*) {
    return {RTSIM_FIELD(TextureRecord, base),  RTSIM_FIELD(TextureRecord, bytes),
            RTSIM_FIELD(TextureRecord, width), RTSIM_FIELD(TextureRecord, height),
            RTSIM_FIELD(TextureRecord, mips),  RTSIM_FIELD(TextureRecord, bytes_per_texel),
            RTSIM_FIELD(TextureRecord, slot),  RTSIM_FIELD(TextureRecord, origin),
            RTSIM_FIELD(TextureRecord, reserved)};
}
inline RecordLayout layout_of(const TriShadeRecord*) {
    return {RTSIM_FIELD(TriShadeRecord, uv), RTSIM_FIELD(TriShadeRecord, material),
            RTSIM_FIELD(TriShadeRecord, lod_base), RTSIM_FIELD(TriShadeRecord, normal)};
}
inline RecordLayout layout_of(const ShadeRecord*) {
    return {RTSIM_FIELD(ShadeRecord, parent),      RTSIM_FIELD(ShadeRecord, material),
            RTSIM_FIELD(ShadeRecord, shader),      RTSIM_FIELD(ShadeRecord, samples),
            RTSIM_FIELD(ShadeRecord, first_fetch), RTSIM_FIELD(ShadeRecord, cone_width),
            RTSIM_FIELD(ShadeRecord, cone_spread)};
}

}  // namespace rtsim
