// The shading arithmetic (traces/shading): texture chains and their addresses, the stand-in
// rule, ray cones and the level they choose, and the texels a hit reads.
#include <gtest/gtest.h>

#include <set>

#include "traces/shading/materials.h"
#include "traces/shading/texels.h"

namespace rtsim {
namespace {

TextureRecord texture(uint32_t w, uint32_t h) {
    Scene scene;
    Material m;
    m.textures[int(TextureSlot::base_color)].source = MaterialTexture::Source::image;
    m.textures[int(TextureSlot::base_color)].width = w;
    m.textures[int(TextureSlot::base_color)].height = h;
    scene.materials.push_back(m);
    return build_shading_scene(scene, "x", false, 1).textures.at(0);
}

TEST(Texels, ChainsTileAndEndWhereTheyClaim) {
    const TextureRecord t = texture(1024, 512);
    EXPECT_EQ(t.mips, 11);                  // 1024 x 512 down to 1 x 1
    EXPECT_EQ(t.base, kTextureBase);  // far above the image and the model's own regions
    // Level 0 is 256 x 128 tiles of 64 bytes; level 1 starts right after it.
    EXPECT_EQ(texel_address(t, 0, 0, 0), t.base);
    EXPECT_EQ(texel_address(t, 0, 3, 3), t.base + 15 * 4);   // one tile: one line
    EXPECT_EQ(texel_address(t, 0, 4, 0), t.base + 64);       // the next tile
    EXPECT_EQ(texel_address(t, 0, 0, 4), t.base + 256 * 64);  // the next tile row
    EXPECT_EQ(texel_address(t, 1, 0, 0), t.base + 1024ull * 512 * 4);
    EXPECT_LT(texel_address(t, 10, 0, 0), t.base + t.bytes);
    EXPECT_GE(texel_address(t, 10, 0, 0) + 64, t.base + t.bytes);  // the last level is one tile
}

TEST(Texels, StandInsFollowTheRule) {
    Scene scene;
    Material baked, stripped, plain;
    baked.textures_baked = true;
    stripped.textures[int(TextureSlot::metallic_roughness)].source = MaterialTexture::Source::stripped;
    scene.materials = {baked, stripped, plain};
    const ShadingScene s = build_shading_scene(scene, "sponza", false, 5);
    ASSERT_EQ(s.textures.size(), 3u);  // base colour + normal, one metallic-roughness, none
    EXPECT_EQ(s.textures[0].width, 1024u);
    EXPECT_EQ(s.textures[1].slot, uint8_t(TextureSlot::normal));
    EXPECT_EQ(s.textures[2].width, 512u);
    for (const TextureRecord& t : s.textures) EXPECT_EQ(t.origin, uint8_t(TextureOrigin::stand_in));
    EXPECT_EQ(s.materials[2].texture[0], -1);
    EXPECT_EQ(s.shaders, 3u);  // three feature sets
    EXPECT_NE(s.materials[0].shader, s.materials[2].shader);
}

TEST(Texels, WiderConesReadCoarserLevels) {
    const TextureRecord t = texture(1024, 1024);
    TriShadeRecord tri{};
    // A unit right triangle mapped onto the whole texture, facing +z.
    const float uv[6] = {0, 0, 1, 0, 0, 1};
    for (int i = 0; i < 6; ++i) tri.uv[i] = uv[i];
    tri.lod_base = 0.0f;  // uv area / world area = 1
    tri.normal[2] = 1.0f;
    const Vec3 dir(0, 0, -1);
    float last = -1e9f;
    for (float w : {1e-4f, 1e-3f, 1e-2f, 1e-1f}) {
        const float lod = ray_cone_lod(tri, t, dir, 1.0f, RayCone{w, 0.0f});
        EXPECT_NEAR(lod, std::log2(w) + 10.0f, 1e-4f);  // one texel per cone width at level 0: 2^-10
        EXPECT_GT(lod, last);
        last = lod;
    }
    // A grazing ray reads a coarser level than a head-on one.
    EXPECT_GT(ray_cone_lod(tri, t, Vec3(1, 0, -0.1f), 1.0f, RayCone{1e-3f, 0}),
              ray_cone_lod(tri, t, dir, 1.0f, RayCone{1e-3f, 0}));
    // A hit's four texels lie in one level, neighbours of each other.
    std::vector<MaterialRecord> mats(1);
    mats[0].texture[0] = 0;
    for (int s = 1; s < kMaterialTextureSlots; ++s) mats[0].texture[s] = -1;
    Hit hit;
    hit.prim = 0, hit.t = 1.0f, hit.u = 0.2505f, hit.v = 0.2505f;  // texel 256.5: x 256 and 257, one tile
    std::vector<uint64_t> out;
    EXPECT_EQ(hit_texels(mats, {t}, tri, hit, dir, RayCone{1e-3f, 0}, &out), 1u);
    ASSERT_EQ(out.size(), 4u);
    EXPECT_EQ(std::set<uint64_t>(out.begin(), out.end()).size(), 4u);
    EXPECT_EQ(out[1] - out[0], 4u);  // x + 1 in the same tile row
}

}  // namespace
}  // namespace rtsim
