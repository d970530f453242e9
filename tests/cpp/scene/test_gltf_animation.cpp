// glTF skins, morph targets and animation samplers: tiny files written here, poses checked
// against hand-computed positions, and malformed skins and keyframes refused by name.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "tests/cpp/scene/gltf_builder.h"
#include "traces/scene/gltf_loader.h"

namespace rtsim {
namespace {

using test::json;

constexpr float kS = 0.70710678f;  // sin 45 degrees

template <typename T>
int data(test::GltfBuilder& b, const std::vector<T>& v, int ct, const char* type, size_t count) {
    return b.accessor(b.view(v.data(), v.size() * sizeof(T)), ct, type, count);
}

/// One triangle (0,0,0), (1,0,0), (0,2,0) on a mesh node translated by (5,0,0), skinned to two
/// joints: j0 at the origin holds v0 and v1, j1 at (0,1,0) (child of j0) holds v2. j1 turns
/// about z from 0 to 90 degrees over one second (LINEAR), unless `joints` / `weight_count`
/// make the file malformed.
struct SkinFile {
    test::GltfBuilder b;
    std::vector<uint16_t> joints = {0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0};
    size_t weight_count = 3;
    float last_angle_sin = kS * kS * 2.0f;  // sin 90 = 1, written as a float expression

    std::string write(const std::string& dir, const std::string& name) {
        int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 2, 0});
        int j = data(b, joints, 5123, "VEC4", 3);
        std::vector<float> w = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
        w.resize(weight_count * 4, 0.0f);
        int wt = data(b, w, 5126, "VEC4", weight_count);
        std::vector<float> ibm = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1,
                                  1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1};
        int ib = data(b, ibm, 5126, "MAT4", 2);
        int times = data(b, std::vector<float>{0.0f, 1.0f}, 5126, "SCALAR", 2);
        // 90 degrees about z: (0, 0, sin 45, cos 45); a NaN `last_angle_sin` poisons it.
        float half_s = std::isfinite(last_angle_sin) ? kS : last_angle_sin, half_c = kS;
        int rot = data(b, std::vector<float>{0, 0, 0, 1, 0, 0, half_s, half_c}, 5126, "VEC4", 2);
        b.mesh("skinned", {{{"attributes", {{"POSITION", pos}, {"JOINTS_0", j}, {"WEIGHTS_0", wt}}}}});
        b.node({{"name", "body"}, {"mesh", 0}, {"skin", 0}, {"translation", {5, 0, 0}}});
        b.node({{"name", "j0"}, {"children", {2}}});
        b.node({{"name", "j1"}, {"translation", {0, 1, 0}}});
        b.doc["skins"] = json::array({{{"joints", {1, 2}}, {"inverseBindMatrices", ib}}});
        b.doc["animations"] = json::array(
            {{{"channels", {{{"sampler", 0}, {"target", {{"node", 2}, {"path", "rotation"}}}}}},
              {"samplers", {{{"input", times}, {"output", rot}, {"interpolation", "LINEAR"}}}}}});
        b.scene({0, 1});
        return b.write(dir, name);
    }
};

void expect_near(const Vec3& got, const Vec3& want, const char* what) {
    EXPECT_NEAR(got.x, want.x, 1e-5f) << what;
    EXPECT_NEAR(got.y, want.y, 1e-5f) << what;
    EXPECT_NEAR(got.z, want.z, 1e-5f) << what;
}

TEST(GltfAnimation, SkinMatchesHandComputedPoses) {
    SkinFile f;
    Scene s = load_gltf(f.write(test::test_dir(), "skin"));
    ASSERT_NE(s.animation, nullptr);
    ASSERT_TRUE(s.animation->deforms(0));
    std::vector<Vec3> p;
    // The pose is in the mesh node's space (its rest transform, T(5,0,0), places the instance):
    // world = global(joint) * inverseBind * v, so the pose is that minus (5,0,0).
    const Vec3 node(5, 0, 0);
    s.animation->pose(0, 0, &p);
    ASSERT_EQ(p.size(), 3u);
    expect_near(p[0], Vec3(0, 0, 0) - node, "frame 0 v0");
    expect_near(p[2], Vec3(0, 2, 0) - node, "frame 0 v2");
    s.animation->pose(0, 30, &p);  // t = 0.5 s: halfway, 45 degrees (slerp)
    expect_near(p[1], Vec3(1, 0, 0) - node, "frame 30 v1 (on j0, still)");
    expect_near(p[2], Vec3(-kS, 1 + kS, 0) - node, "frame 30 v2");
    s.animation->pose(0, 15, &p);  // t = 0.25 s: 22.5 degrees
    const float a = 0.39269908f;
    expect_near(p[2], Vec3(-std::sin(a), 1 + std::cos(a), 0) - node, "frame 15 v2");
    // The instance stays where the loader puts it today: the mesh node's transform.
    EXPECT_EQ(s.instances.at(0).object_to_world[3][0], 5.0);
}

/// One triangle with one morph target moving v2 by (0,0,1); its weight animated by `sampler`.
std::string write_morph(const std::string& dir, const std::string& interpolation,
                        const std::vector<float>& output) {
    test::GltfBuilder b;
    int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
    int delta = b.positions({0, 0, 0, 0, 0, 0, 0, 0, 1});
    int times = data(b, std::vector<float>{0.0f, 1.0f}, 5126, "SCALAR", 2);
    int out = data(b, output, 5126, "SCALAR", output.size());
    b.doc["meshes"] = json::array({{{"name", "morph"},
                                    {"weights", {0.0}},
                                    {"primitives", {{{"attributes", {{"POSITION", pos}}},
                                                     {"targets", {{{"POSITION", delta}}}}}}}}});
    b.node({{"mesh", 0}});
    b.doc["animations"] = json::array(
        {{{"channels", {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "weights"}}}}}},
          {"samplers", {{{"input", times}, {"output", out}, {"interpolation", interpolation}}}}}});
    b.scene({0});
    return b.write(dir, "morph_" + interpolation);
}

float morph_z(const Scene& s, uint32_t frame) {
    std::vector<Vec3> p;
    s.animation->pose(0, frame, &p);
    return p.at(2).z;
}

TEST(GltfAnimation, MorphWeightsLinearStepCubic) {
    const std::string dir = test::test_dir();
    Scene linear = load_gltf(write_morph(dir, "LINEAR", {0.0f, 1.0f}));
    ASSERT_NE(linear.animation, nullptr);
    EXPECT_NEAR(morph_z(linear, 0), 0.0f, 1e-6f);
    EXPECT_NEAR(morph_z(linear, 15), 0.25f, 1e-6f);
    EXPECT_NEAR(morph_z(linear, 45), 0.75f, 1e-6f);
    Scene step = load_gltf(write_morph(dir, "STEP", {0.0f, 1.0f}));
    EXPECT_EQ(morph_z(step, 45), 0.0f);
    EXPECT_EQ(morph_z(step, 59), 0.0f);
    // CUBICSPLINE: (in-tangent, value, out-tangent) per keyframe; out-tangent 2 at t = 0.
    // p(u) = (u^3 - 2u^2 + u) * 2 + (-2u^3 + 3u^2) * 1; u = 0.25: 0.28125 + 0.15625 = 0.4375.
    Scene cubic = load_gltf(write_morph(dir, "CUBICSPLINE", {0, 0, 2, 0, 1, 0}));
    EXPECT_NEAR(morph_z(cubic, 15), 0.4375f, 1e-6f);
    EXPECT_NEAR(morph_z(cubic, 30), 0.5f + 0.25f, 1e-6f);  // 0.125 * 2 + 0.5
}

TEST(GltfAnimation, MalformedSkinsAndKeyframesRefusedByName) {
    const std::string dir = test::test_dir();
    SkinFile bad_joint;
    bad_joint.joints[8] = 5;
    test::expect_error(bad_joint.write(dir, "bad_joint"), {"skin 0", "names joint 5", "2 joints"});
    SkinFile bad_weights;
    bad_weights.weight_count = 2;
    test::expect_error(bad_weights.write(dir, "bad_weights"), {"skin 0", "WEIGHTS_0"});
    SkinFile bad_key;
    bad_key.last_angle_sin = std::numeric_limits<float>::quiet_NaN();
    test::expect_error(bad_key.write(dir, "bad_key"), {"animation 0 sampler 0", "not finite"});
}

}  // namespace
}  // namespace rtsim
