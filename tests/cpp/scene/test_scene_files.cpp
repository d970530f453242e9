// The shared scenes (RTSIM_SCENES_DIR, see its README.md) load with the documented counts.
#include <chrono>
#include <filesystem>
#include <iostream>

#include <gtest/gtest.h>

#include "traces/scene/gltf_loader.h"

namespace rtsim {
namespace {

std::string scene_path(const std::string& rel) {
    std::string path = std::string(RTSIM_SCENES_DIR) + "/" + rel;
    return path;
}

/// Loads a shared scene, timing it; skips the test if the shared folder is absent.
Scene load_timed(const std::string& rel) {
    std::string path = scene_path(rel);
    if (!std::filesystem::exists(path)) return Scene{};
    auto t0 = std::chrono::steady_clock::now();
    Scene s = load_gltf(path);
    double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::cout << "[ time     ] load " << rel << ": " << ms << " ms, " << s.triangle_count() << " triangles\n";
    ::testing::Test::RecordProperty("load_ms_" + std::filesystem::path(rel).stem().string(), int(ms));
    return s;
}

#define LOAD_OR_SKIP(var, rel)                                                      \
    Scene var = load_timed(rel);                                                    \
    if (var.source.empty()) GTEST_SKIP() << "shared scene missing: " << scene_path(rel)

size_t count_mode(const Scene& s, AlphaMode mode) {
    size_t n = 0;
    for (const Material& m : s.materials) n += m.alpha_mode == mode;
    return n;
}

TEST(SceneFiles, Sponza) {
    LOAD_OR_SKIP(s, "sponza/Sponza.gltf");
    EXPECT_EQ(s.triangle_count(), 262267u);
    EXPECT_EQ(s.materials.size(), 25u);
    EXPECT_EQ(count_mode(s, AlphaMode::mask), 3u);
    EXPECT_FLOAT_EQ(s.materials[0].alpha_coverage, 0.442f);  // leaf
    EXPECT_FALSE(s.uses_instancing());
    // README bounds x 0.008 node scale.
    EXPECT_NEAR(s.bounds.lo.x, -1920.9f * 0.008f, 0.01f);
    EXPECT_NEAR(s.bounds.hi.y, 1429.4f * 0.008f, 0.01f);
    EXPECT_NEAR(s.bounds.lo.z, -1182.8f * 0.008f, 0.01f);
    EXPECT_TRUE(s.lights.empty());
}

TEST(SceneFiles, Bunny) {
    LOAD_OR_SKIP(s, "stanford_bunny/bunny.gltf");
    EXPECT_EQ(s.triangle_count(), 144046u);
    EXPECT_EQ(s.materials.size(), 1u);
}

TEST(SceneFiles, MetalRoughSpheres) {
    LOAD_OR_SKIP(s, "MetalRoughSpheresNoTextures/MetalRoughSpheresNoTextures.gltf");
    EXPECT_EQ(s.triangle_count(), 1040409u);
    // 98 glTF materials plus the default one for the primitives that have none.
    ASSERT_EQ(s.materials.size(), 99u);
    EXPECT_EQ(s.materials.back().name, "rtsim_default");
    s.materials.pop_back();
    // Metallic and roughness both span the grid.
    float mmin = 1, mmax = 0, rmin = 1, rmax = 0;
    for (const Material& m : s.materials) {
        mmin = std::min(mmin, m.metallic), mmax = std::max(mmax, m.metallic);
        rmin = std::min(rmin, m.roughness), rmax = std::max(rmax, m.roughness);
    }
    EXPECT_LT(mmin, 0.1f);
    EXPECT_GT(mmax, 0.9f);
    EXPECT_LT(rmin, 0.1f);
    EXPECT_GT(rmax, 0.9f);
}

TEST(SceneFiles, SimpleInstancing) {
    LOAD_OR_SKIP(s, "SimpleInstancing/SimpleInstancing.gltf");
    EXPECT_EQ(s.triangle_count(), 1500u);
    EXPECT_EQ(s.instances.size(), 125u);
    EXPECT_EQ(s.meshes.size(), 1u);
    EXPECT_TRUE(s.uses_instancing());
    // Instances are spread over the 10^3 translation grid, not stacked.
    EXPECT_GT(s.bounds.extent().x, 9.0f);
    EXPECT_GT(s.bounds.extent().y, 9.0f);
}

TEST(SceneFiles, LightsPunctualLamp) {
    LOAD_OR_SKIP(s, "LightsPunctualLamp/LightsPunctualLamp.gltf");
    EXPECT_EQ(s.triangle_count(), 6000u);
    ASSERT_EQ(s.lights.size(), 5u);
    for (const Light& l : s.lights) EXPECT_EQ(l.type, LightType::point);
    EXPECT_FLOAT_EQ(s.lights[0].intensity, 15.0f);
    bool transmission = false, emissive = false;
    for (const Material& m : s.materials) {
        transmission |= m.transmission > 0.0f;
        emissive |= m.is_emissive();
    }
    EXPECT_TRUE(transmission);
    EXPECT_TRUE(emissive);
    EXPECT_EQ(count_mode(s, AlphaMode::blend), 1u);
    // Lights sit inside the lamp's bounds (roughly), not at the origin.
    for (const Light& l : s.lights) EXPECT_GT(glm::length(l.position), 0.1f);
}

TEST(SceneFiles, AlphaBlendModeTest) {
    LOAD_OR_SKIP(s, "AlphaBlendModeTest/AlphaBlendModeTest.gltf");
    EXPECT_EQ(s.triangle_count(), 61u);
    EXPECT_EQ(count_mode(s, AlphaMode::mask), 3u);
    std::vector<float> cutoffs;
    for (const Material& m : s.materials)
        if (m.alpha_mode == AlphaMode::mask) cutoffs.push_back(m.alpha_cutoff);
    std::sort(cutoffs.begin(), cutoffs.end());
    ASSERT_EQ(cutoffs.size(), 3u);
    EXPECT_FLOAT_EQ(cutoffs[0], 0.25f);
    EXPECT_FLOAT_EQ(cutoffs[1], 0.5f);
    EXPECT_FLOAT_EQ(cutoffs[2], 0.75f);
    EXPECT_EQ(count_mode(s, AlphaMode::blend), 1u);
}

}  // namespace
}  // namespace rtsim
