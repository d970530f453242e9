// Procedural scenes: written as glTF, reloaded, with plausible counts, bounds, lights and cameras;
// deterministic for a seed.
#include <array>
#include <chrono>
#include <fstream>
#include <iostream>
#include <iterator>

#include <gtest/gtest.h>

#include "tests/cpp/scene/gltf_builder.h"
#include "traces/common/error.h"
#include "traces/scene/gltf_loader.h"
#include "traces/scene/procedural.h"

namespace rtsim {
namespace {

std::string read_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

bool has_material(const Scene& s, float metallic, float roughness_below) {
    for (const Material& m : s.materials)
        if (m.metallic == metallic && m.roughness < roughness_below) return true;
    return false;
}

TEST(Procedural, NamesAndUnknownName) {
    EXPECT_EQ(procedural_scene_names().size(), 10u);
    EXPECT_TRUE(is_procedural_scene("hairball"));
    EXPECT_FALSE(is_procedural_scene("sponza"));
    try {
        write_procedural_scene("sponzaa", test::test_dir());
        ADD_FAILURE() << "no error for an unknown scene";
    } catch (const Error& e) {
        std::string msg = e.what();
        EXPECT_NE(msg.find("sponzaa"), std::string::npos);
        for (const std::string& n : procedural_scene_names()) EXPECT_NE(msg.find(n), std::string::npos) << msg;
    }
}

TEST(Procedural, Cornell) {
    Scene s = load_gltf(write_procedural_scene("cornell", test::test_dir()));
    EXPECT_GT(s.triangle_count(), 3000u);
    EXPECT_TRUE(s.lights.empty());  // lit by the emissive quad only
    ASSERT_EQ(s.cameras.size(), 1u);
    EXPECT_NEAR(s.bounds.lo.y, 0.0f, 1e-4f);
    EXPECT_NEAR(s.bounds.hi.x, 5.55f, 1e-4f);
    size_t emissive = 0;
    for (size_t t = 0; t < s.triangle_count(); ++t) emissive += s.materials[s.tri_material[t]].is_emissive();
    EXPECT_EQ(emissive, 2u);
    EXPECT_GT(s.materials[s.tri_material[0]].base_color.x, 0.5f);
    EXPECT_TRUE(has_material(s, 1.0f, 0.01f));  // the mirror box
    // The camera is outside the open front, looking into the box (+z).
    EXPECT_LT(s.cameras[0].eye.z, 0.0f);
    EXPECT_GT(s.cameras[0].forward.z, 0.99f);
    // The light quad faces down.
    for (size_t t = 0; t < s.triangle_count(); ++t)
        if (s.materials[s.tri_material[t]].is_emissive()) {
            const Triangle& tri = s.triangles[t];
            EXPECT_LT(glm::cross(tri.v1 - tri.v0, tri.v2 - tri.v0).y, 0.0f);
        }
}

TEST(Procedural, HairballExactCountInsideBallAndDeterministic) {
    std::string dir = test::test_dir();
    ProceduralOptions opt;
    opt.hairball_triangles = 10001;
    std::string path = write_procedural_scene("hairball", dir + "/a", opt);
    Scene s = load_gltf(path);
    EXPECT_EQ(s.triangle_count(), 10001u);
    EXPECT_GE(s.bounds.lo.x, -1.01f);
    EXPECT_LE(s.bounds.hi.y, 1.01f);
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].type, LightType::point);
    ASSERT_EQ(s.cameras.size(), 1u);
    EXPECT_GT(glm::length(s.cameras[0].eye), 1.5f);
    EXPECT_GT(glm::dot(s.cameras[0].forward, -glm::normalize(s.cameras[0].eye)), 0.99f);
    // Same seed, same bytes; another seed, other bytes.
    std::string again = write_procedural_scene("hairball", dir + "/b", opt);
    EXPECT_EQ(read_bytes(dir + "/a/hairball.bin"), read_bytes(dir + "/b/hairball.bin"));
    opt.seed = 2;
    write_procedural_scene("hairball", dir + "/c", opt);
    EXPECT_NE(read_bytes(dir + "/a/hairball.bin"), read_bytes(dir + "/c/hairball.bin"));
    (void)again;
}

TEST(Procedural, HairballMillion) {
    ProceduralOptions opt;
    opt.hairball_triangles = 1000000;
    auto t0 = std::chrono::steady_clock::now();
    std::string path = write_procedural_scene("hairball", test::test_dir(), opt);
    auto t1 = std::chrono::steady_clock::now();
    Scene s = load_gltf(path);
    auto t2 = std::chrono::steady_clock::now();
    auto ms = [](auto a, auto b) { return std::chrono::duration<double, std::milli>(b - a).count(); };
    std::cout << "[ time     ] hairball 1M: generate+write " << ms(t0, t1) << " ms, load " << ms(t1, t2)
              << " ms\n";
    RecordProperty("generate_ms", int(ms(t0, t1)));
    RecordProperty("load_ms", int(ms(t1, t2)));
    EXPECT_EQ(s.triangle_count(), 1000000u);
}

TEST(Procedural, TeapotStadium) {
    Scene s = load_gltf(write_procedural_scene("teapot_stadium", test::test_dir()));
    ASSERT_EQ(s.meshes.size(), 2u);
    size_t teapot = s.meshes[0].triangle_count(), stadium = s.meshes[1].triangle_count();
    EXPECT_GE(teapot, 10000u);
    EXPECT_LE(teapot, 50000u);
    EXPECT_LT(stadium, teapot / 4);
    Aabb tea;
    for (const Vec3& p : s.meshes[0].positions) tea.grow(p);
    EXPECT_GT(s.bounds.extent().x, 500.0f * tea.extent().x);
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].type, LightType::directional);
    EXPECT_LT(s.lights[0].direction.y, -0.5f);  // the sun shines down
    ASSERT_EQ(s.cameras.size(), 1u);
    EXPECT_LT(glm::length(s.cameras[0].eye - tea.center()), 10.0f);
}

TEST(Procedural, MeadowHasAlphaTestedGrassCardsOnTheTerrainsHills) {
    Scene s = load_gltf(write_procedural_scene("meadow", test::test_dir()));
    EXPECT_EQ(s.triangle_count(), 2u * 128 * 128 + 2u * 8000);
    ASSERT_EQ(s.lights.size(), 1u);
    // The cards' material is MASK with the coverage the writer gave it; the ground is opaque.
    int masked = 0;
    for (const Material& m : s.materials)
        if (m.alpha_mode == AlphaMode::mask) {
            ++masked;
            EXPECT_NEAR(m.alpha_coverage, 0.35f, 1e-6f);
        }
    EXPECT_EQ(masked, 1);
    size_t card_triangles = 0;
    for (size_t t = 0; t < s.triangle_count(); ++t)
        card_triangles += s.materials[s.tri_material[t]].alpha_mode == AlphaMode::mask;
    EXPECT_EQ(card_triangles, 2u * 8000);
    EXPECT_NEAR(s.bounds.extent().x, 80.0f, 1.5f);
}

TEST(Procedural, TerrainIsAnEvenlyCoveredHeightFieldUnderASun) {
    Scene s = load_gltf(write_procedural_scene("terrain", test::test_dir()));
    EXPECT_EQ(s.triangle_count(), 2u * 128 * 128 + 3u * 12000);
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].type, LightType::directional);
    EXPECT_LT(s.lights[0].direction.y, -0.5f);
    // A field 80 m across and a few metres high: blades and ground spread evenly over it, so
    // each quarter of the field holds about a quarter of the triangles.
    EXPECT_NEAR(s.bounds.extent().x, 80.0f, 0.5f);
    EXPECT_LT(s.bounds.extent().y, 8.0f);
    std::array<size_t, 4> quarter{};
    for (size_t t = 0; t < s.triangle_count(); ++t) {
        const Triangle& tri = s.triangles[t];
        const Vec3 c = (tri.v0 + tri.v1 + tri.v2) / 3.0f;
        ++quarter[size_t(c.x > 0) * 2 + size_t(c.z > 0)];
    }
    for (size_t q : quarter) EXPECT_NEAR(double(q) / double(s.triangle_count()), 0.25, 0.02);
    // Deterministic for a seed, different for another.
    const std::string dir = test::test_dir();
    ProceduralOptions opt;
    write_procedural_scene("terrain", dir + "/a", opt);
    write_procedural_scene("terrain", dir + "/b", opt);
    opt.seed = 2;
    write_procedural_scene("terrain", dir + "/c", opt);
    EXPECT_EQ(read_bytes(dir + "/a/terrain.bin"), read_bytes(dir + "/b/terrain.bin"));
    EXPECT_NE(read_bytes(dir + "/a/terrain.bin"), read_bytes(dir + "/c/terrain.bin"));
}

TEST(Procedural, RotatedWalls) {
    Scene s = load_gltf(write_procedural_scene("rotated_walls", test::test_dir()));
    EXPECT_GT(s.triangle_count(), 100u);
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].type, LightType::point);
    EXPECT_TRUE(has_material(s, 1.0f, 0.1f));
    // Most wall faces are neither axis-aligned nor horizontal: AABBs fit badly.
    size_t oblique = 0;
    for (const Triangle& t : s.triangles) {
        Vec3 n = glm::normalize(glm::cross(t.v1 - t.v0, t.v2 - t.v0));
        float m = std::max({std::abs(n.x), std::abs(n.y), std::abs(n.z)});
        oblique += m < 0.99f;
    }
    EXPECT_GT(oblique, s.triangle_count() / 2);
    EXPECT_GT(s.bounds.extent().x, 20.0f);
}

TEST(Procedural, AlignedWallsAreTheRotatedWallsTwin) {
    Scene aligned = load_gltf(write_procedural_scene("aligned_walls", test::test_dir()));
    Scene rotated = load_gltf(write_procedural_scene("rotated_walls", test::test_dir()));
    // The same maze, so the same triangles, with every face on the axes.
    EXPECT_EQ(aligned.triangle_count(), rotated.triangle_count());
    for (const Triangle& t : aligned.triangles) {
        Vec3 n = glm::normalize(glm::cross(t.v1 - t.v0, t.v2 - t.v0));
        EXPECT_GT(std::max({std::abs(n.x), std::abs(n.y), std::abs(n.z)}), 0.9999f);
    }
    EXPECT_TRUE(has_material(aligned, 1.0f, 0.1f));
    EXPECT_EQ(aligned.lights.size(), 1u);
}

}  // namespace
}  // namespace rtsim
