// The procedural deforming scenes: Scene::animation set, deterministic and finite poses over 60
// frames with constant triangle counts, the motion they promise, and malformed motions refused.
#include <cmath>
#include <fstream>
#include <iterator>

#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>

#include "tests/cpp/scene/gltf_builder.h"
#include "traces/common/error.h"
#include "traces/scene/gltf_loader.h"
#include "traces/scene/procedural.h"

namespace rtsim {
namespace {

bool all_finite(const std::vector<Vec3>& v) {
    for (const Vec3& p : v)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return false;
    return true;
}

/// The one deforming mesh of a procedural moving scene.
uint32_t deforming_mesh(const Scene& s) {
    uint32_t found = 0, count = 0;
    for (uint32_t m = 0; m < s.meshes.size(); ++m)
        if (s.animation->deforms(m)) found = m, ++count;
    EXPECT_EQ(count, 1u);
    return found;
}

class MovingScene : public ::testing::TestWithParam<const char*> {};

TEST_P(MovingScene, DeterministicFiniteConstantCountOver60Frames) {
    Scene s = load_gltf(write_procedural_scene(GetParam(), test::test_dir()));
    ASSERT_NE(s.animation, nullptr);
    EXPECT_FALSE(s.animation->description().empty());
    EXPECT_EQ(s.animation->frames_per_second(), 60.0);
    ASSERT_FALSE(s.cameras.empty());
    ASSERT_FALSE(s.lights.empty());
    const uint32_t mesh = deforming_mesh(s);
    const size_t corners = s.meshes[mesh].positions.size();
    std::vector<Vec3> pose, again;
    s.animation->pose(mesh, 0, &pose);
    // The scatter starts from the pose written; the cloth's wave is already under way at t = 0.
    if (std::string(GetParam()) == "exploding_hairball") EXPECT_EQ(pose, s.meshes[mesh].positions);
    std::vector<Vec3> previous = pose;
    for (uint32_t f = 1; f <= 60; ++f) {
        s.animation->pose(mesh, f, &pose);
        ASSERT_EQ(pose.size(), corners) << "frame " << f;
        ASSERT_TRUE(all_finite(pose)) << "frame " << f;
        EXPECT_NE(pose, previous) << "frame " << f << " did not move";
        previous = pose;
    }
    s.animation->pose(mesh, 37, &pose);
    s.animation->pose(mesh, 37, &again);
    EXPECT_EQ(pose, again);
    // A second load of a second write gives the same bits.
    Scene t = load_gltf(write_procedural_scene(GetParam(), test::test_dir()));
    t.animation->pose(mesh, 37, &again);
    EXPECT_EQ(pose, again);
}

INSTANTIATE_TEST_SUITE_P(Procedural, MovingScene, ::testing::Values("cloth", "exploding_hairball", "skinned_tube"));

TEST(MovingScene, StillScenesHaveNoAnimation) {
    EXPECT_EQ(load_gltf(write_procedural_scene("cornell", test::test_dir())).animation, nullptr);
}

TEST(MovingScene, ClothIsAGridWithATravellingWave) {
    Scene s = load_gltf(write_procedural_scene("cloth", test::test_dir()));
    const uint32_t mesh = deforming_mesh(s);
    const size_t tris = s.meshes[mesh].triangle_count();
    EXPECT_GE(tris, 20000u);
    EXPECT_LE(tris, 50000u);
    // The pinned edge (smallest x) stays still; the free edge moves, within the amplitude.
    std::vector<Vec3> rest = s.meshes[mesh].positions, pose;
    s.animation->pose(mesh, 15, &pose);
    float x_min = rest[0].x, max_dy = 0.0f;
    for (const Vec3& v : rest) x_min = std::min(x_min, v.x);
    for (size_t i = 0; i < rest.size(); ++i) {
        EXPECT_EQ(pose[i].x, rest[i].x);
        EXPECT_EQ(pose[i].z, rest[i].z);
        if (rest[i].x == x_min) {
            EXPECT_NEAR(pose[i].y, rest[i].y, 1e-6f);
        }
        max_dy = std::max(max_dy, std::abs(pose[i].y - rest[i].y));
    }
    EXPECT_GT(max_dy, 0.05f);
    EXPECT_LE(max_dy, 0.25f + 1e-5f);
}

TEST(MovingScene, HairballTrianglesMoveRigidlyOutward) {
    Scene s = load_gltf(write_procedural_scene("exploding_hairball", test::test_dir()));
    const uint32_t mesh = deforming_mesh(s);
    std::vector<Vec3> rest = s.meshes[mesh].positions, pose;
    s.animation->pose(mesh, 60, &pose);
    for (size_t t = 0; t < rest.size() / 3; t += 97) {
        Vec3 d0 = pose[3 * t] - rest[3 * t], d1 = pose[3 * t + 1] - rest[3 * t + 1];
        EXPECT_LT(glm::length(d0 - d1), 1e-4f) << "triangle " << t << " is not rigid";
        Vec3 c = (rest[3 * t] + rest[3 * t + 1] + rest[3 * t + 2]) / 3.0f;
        EXPECT_GT(glm::dot(d0, c), 0.0f) << "triangle " << t << " moves inward";
        // Speeds in [0.2, 2] m/s over one second.
        EXPECT_GE(glm::length(d0), 0.2f - 1e-4f);
        EXPECT_LE(glm::length(d0), 2.0f + 1e-4f);
    }
}

TEST(MovingScene, SkinnedTubeFollowsItsJointsAndLoops) {
    // The tube is a glTF skin (JOINTS_0/WEIGHTS_0, a chain of 8 joints, LINEAR rotation channels),
    // so its poses come through the loader's skinning: checked against the joints by hand.
    Scene s = load_gltf(write_procedural_scene("skinned_tube", test::test_dir()));
    const uint32_t mesh = deforming_mesh(s);
    EXPECT_EQ(s.meshes[mesh].triangle_count(), 2u * 48u * 128u);
    std::vector<Vec3> rest = s.meshes[mesh].positions, pose, later;
    // The bottom ring is bound to the root joint alone, at the origin: p' = R0(t) p, where the
    // root's rotation at a key time (frame 30: t = 0.5 s = key 15 of 61 over 2 s) is the written
    // sway of the scene: angle 0.22 sin(phase) about z after 0.11 cos(phase) about x.
    const float phase = float(2.0 * 3.14159265358979323846) * 0.5f / 2.0f;
    const glm::quat r0 = glm::angleAxis(0.22f * std::sin(phase), glm::vec3(0, 0, 1)) *
                         glm::angleAxis(0.11f * std::cos(phase), glm::vec3(1, 0, 0));
    s.animation->pose(mesh, 30, &pose);
    size_t bottom = 0;
    for (size_t i = 0; i < rest.size(); ++i) {
        if (rest[i].y != 0.0f) continue;
        ++bottom;
        const Vec3 expect = r0 * rest[i];
        EXPECT_NEAR(pose[i].x, expect.x, 1e-5f) << "corner " << i;
        EXPECT_NEAR(pose[i].y, expect.y, 1e-5f) << "corner " << i;
        EXPECT_NEAR(pose[i].z, expect.z, 1e-5f) << "corner " << i;
    }
    EXPECT_GT(bottom, 0u);
    // Skinning bends, never stretches much: every corner stays within the tube's length of the
    // root, and the top moves away from the rest pose.
    float top_moved = 0.0f;
    for (size_t i = 0; i < rest.size(); ++i) {
        EXPECT_LE(glm::length(pose[i]), 2.0f + 0.2f) << "corner " << i;
        if (rest[i].y == 2.0f) top_moved = std::max(top_moved, glm::length(pose[i] - rest[i]));
    }
    EXPECT_GT(top_moved, 0.3f);
    // The sway loops every 2 s (120 frames at 60 fps).
    s.animation->pose(mesh, 150, &later);
    for (size_t i = 0; i < pose.size(); i += 101) EXPECT_LT(glm::length(later[i] - pose[i]), 1e-4f) << "corner " << i;
}

TEST(MovingScene, MalformedMotionRefusedNamingTheMesh) {
    const std::string dir = test::test_dir();  // once: each call empties the folder
    std::string path = write_procedural_scene("cloth", dir);
    std::ifstream in(path);
    std::string json((std::istreambuf_iterator<char>(in)), {});
    in.close();
    const std::string bad_path = dir + "/cloth_bad_motion.gltf";
    auto refuse = [&](const std::string& from, const std::string& to, const std::string& expect) {
        std::string text = json;
        size_t at = text.find(from);
        ASSERT_NE(at, std::string::npos) << from;
        text.replace(at, from.size(), to);
        std::ofstream(bad_path) << text;
        try {
            load_gltf(bad_path);
            ADD_FAILURE() << "no error for " << to;
        } catch (const Error& e) {
            std::string msg = e.what();
            EXPECT_NE(msg.find("cloth_bad_motion.gltf"), std::string::npos) << msg;
            EXPECT_NE(msg.find("mesh 0 'cloth'"), std::string::npos) << msg;
            EXPECT_NE(msg.find(expect), std::string::npos) << msg;
        }
    };
    refuse("\"wave\"", "\"wobble\"", "kind 'wobble' unknown");
    refuse("\"period\"", "\"period\": \"x\", \"unused\"", "'period' is not a finite number");
}

}  // namespace
}  // namespace rtsim
