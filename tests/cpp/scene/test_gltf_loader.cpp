// load_gltf on tiny hand-written files: node transforms, index types, strips and fans, instancing,
// materials, lights and cameras.
#include <gtest/gtest.h>

#include "tests/cpp/scene/gltf_builder.h"
#include "traces/scene/gltf_loader.h"

namespace rtsim {
namespace {

using test::GltfBuilder;
using test::json;

void expect_near(const Vec3& a, const Vec3& b, float eps = 1e-5f) {
    EXPECT_NEAR(a.x, b.x, eps);
    EXPECT_NEAR(a.y, b.y, eps);
    EXPECT_NEAR(a.z, b.z, eps);
}

Vec3 normal(const Triangle& t) { return glm::cross(t.v1 - t.v0, t.v2 - t.v0); }

TEST(GltfLoader, ComposesTrsParentWithMatrixChild) {
    GltfBuilder b = test::one_triangle();
    // Parent: T(1,2,3) R(90 deg about Y) S(2); child: matrix translating by (0,0,1), with the mesh.
    b.doc["nodes"] = json::array();
    b.node({{"translation", {1, 2, 3}}, {"rotation", {0, 0.70710678118654752, 0, 0.70710678118654752}},
            {"scale", {2, 2, 2}}, {"children", {1}}});
    b.node({{"mesh", 0}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 1}}});
    b.scene({0});
    Scene s = load_gltf(b.write(test::test_dir(), "trs"));
    ASSERT_EQ(s.triangle_count(), 1u);
    // By hand: v -> T(R(S(v + (0,0,1)))), R_y(90): (x,y,z) -> (z,y,-x).
    expect_near(s.triangles[0].v0, {3, 2, 3});
    expect_near(s.triangles[0].v1, {3, 2, 1});
    expect_near(s.triangles[0].v2, {3, 4, 3});
    EXPECT_EQ(s.instances.at(0).node, 1);
    EXPECT_FALSE(s.uses_instancing());
    EXPECT_EQ(s.tri_material[0], s.default_material());
}

TEST(GltfLoader, SharedMeshGivesOneMeshAndTwoInstances) {
    GltfBuilder b = test::one_triangle();
    b.node({{"mesh", 0}, {"translation", {0, 0, 10}}});
    b.scene({0, 1});
    Scene s = load_gltf(b.write(test::test_dir(), "shared", false));
    EXPECT_EQ(s.meshes.size(), 1u);
    ASSERT_EQ(s.instances.size(), 2u);
    EXPECT_TRUE(s.uses_instancing());
    EXPECT_EQ(s.instances[1].prim_base, 1u);
    expect_near(s.triangles[1].v0, {0, 0, 10});
    EXPECT_EQ(s.tri_instance[1], 1u);
}

TEST(GltfLoader, ReadsEveryIndexTypeAndNonIndexed) {
    GltfBuilder b;
    int pos = b.positions({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0});
    int i8 = b.indices(std::vector<uint8_t>{0, 1, 2, 0, 2, 3});
    int i16 = b.indices(std::vector<uint16_t>{0, 1, 2, 0, 2, 3});
    int i32 = b.indices(std::vector<uint32_t>{0, 1, 2, 0, 2, 3});
    int flat = b.positions({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 0, 0, 1, 1, 0, 0, 1, 0});
    json attr = {{"POSITION", pos}};
    b.mesh("quads", {{{"attributes", attr}, {"indices", i8}},
                     {{"attributes", attr}, {"indices", i16}},
                     {{"attributes", attr}, {"indices", i32}},
                     {{"attributes", {{"POSITION", flat}}}}});
    b.node({{"mesh", 0}});
    b.scene({0});
    Scene s = load_gltf(b.write(test::test_dir(), "indices"));
    ASSERT_EQ(s.triangle_count(), 8u);
    for (size_t t = 0; t < 8; t += 2) {
        expect_near(s.triangles[t].v1, {1, 0, 0});
        expect_near(s.triangles[t + 1].v2, {0, 1, 0});
        EXPECT_GT(normal(s.triangles[t]).z, 0.0f);
        EXPECT_GT(normal(s.triangles[t + 1]).z, 0.0f);
    }
}

TEST(GltfLoader, StripsAndFansBecomeListsWithConsistentWinding) {
    GltfBuilder b;
    // A zig-zag strip of 5 vertices (3 clockwise triangles seen from +Z) and a fan of 5 vertices
    // (3 counter-clockwise triangles): conversion must keep each primitive's winding.
    int strip = b.positions({0, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1, 0, 2, 0, 0});
    int fan = b.positions({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, -1, 1, 0});
    int fan_idx = b.indices(std::vector<uint16_t>{0, 1, 2, 3, 4});
    b.mesh("strip_fan", {{{"attributes", {{"POSITION", strip}}}, {"mode", 5}},
                         {{"attributes", {{"POSITION", fan}}}, {"indices", fan_idx}, {"mode", 6}}});
    b.node({{"mesh", 0}});
    b.scene({0});
    Scene s = load_gltf(b.write(test::test_dir(), "strip_fan"));
    ASSERT_EQ(s.triangle_count(), 6u);
    for (size_t t = 0; t < 3; ++t) EXPECT_LT(normal(s.triangles[t]).z, 0.0f) << "strip triangle " << t;
    for (size_t t = 3; t < 6; ++t) EXPECT_GT(normal(s.triangles[t]).z, 0.0f) << "fan triangle " << t;
    // Strip triangle 1 = {1, 3, 2}; fan triangle 0 = {1, 2, 0}.
    expect_near(s.triangles[1].v0, {0, 1, 0});
    expect_near(s.triangles[1].v1, {1, 1, 0});
    expect_near(s.triangles[3].v2, {0, 0, 0});
}

TEST(GltfLoader, GpuInstancingAppliesNodeThenInstanceTransform) {
    GltfBuilder b = test::one_triangle();
    int t = b.positions({0, 0, 0, 0, 5, 0});
    b.doc["nodes"][0]["translation"] = {10, 0, 0};
    b.doc["nodes"][0]["scale"] = {2, 2, 2};
    b.doc["nodes"][0]["extensions"] = {{"EXT_mesh_gpu_instancing", {{"attributes", {{"TRANSLATION", t}}}}}};
    b.doc["extensionsUsed"] = {"EXT_mesh_gpu_instancing"};
    Scene s = load_gltf(b.write(test::test_dir(), "gpu_inst"));
    ASSERT_EQ(s.instances.size(), 2u);
    EXPECT_TRUE(s.uses_instancing());
    expect_near(s.triangles[1].v0, {10, 10, 0});  // node scale applies to the instance offset
    expect_near(s.triangles[1].v2, {10, 12, 0});
}

TEST(GltfLoader, MaterialsLightsAndCameras) {
    GltfBuilder b = test::one_triangle();
    b.doc["materials"] = json::array({{{"name", "glass"},
                                       {"alphaMode", "MASK"},
                                       {"alphaCutoff", 0.3},
                                       {"emissiveFactor", {1, 0.5, 0}},
                                       {"extras", {{"textureAlphaCoverage", 0.4}}},
                                       {"extensions",
                                        {{"KHR_materials_transmission", {{"transmissionFactor", 0.7}}},
                                         {"KHR_materials_ior", {{"ior", 1.33}}},
                                         {"KHR_materials_emissive_strength", {{"emissiveStrength", 4.0}}}}}}});
    b.doc["meshes"][0]["primitives"][0]["material"] = 0;
    b.doc["extensions"] = {{"KHR_lights_punctual",
                            {{"lights", {{{"type", "spot"}, {"intensity", 3.0}, {"color", {1, 0, 0}},
                                          {"spot", {{"outerConeAngle", 0.5}}}}}}}}};
    b.doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.1}}}},
                        {{"type", "orthographic"},
                         {"orthographic", {{"xmag", 1}, {"ymag", 1}, {"znear", 0.1}, {"zfar", 10}}}}};
    // Light at (0,5,0) turned 90 deg about X: -Z becomes -Y (points down). Cameras at z = 5 and 6.
    b.node({{"translation", {0, 5, 0}}, {"rotation", {-0.70710678118654752, 0, 0, 0.70710678118654752}},
            {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    b.node({{"translation", {0, 0, 5}}, {"camera", 0}});
    b.node({{"translation", {0, 0, 6}}, {"camera", 1}});
    b.scene({0, 1, 2, 3});
    Scene s = load_gltf(b.write(test::test_dir(), "mat_light_cam"));
    const Material& m = s.materials.at(0);
    EXPECT_EQ(m.alpha_mode, AlphaMode::mask);
    EXPECT_FLOAT_EQ(m.alpha_cutoff, 0.3f);
    EXPECT_FLOAT_EQ(m.alpha_coverage, 0.4f);
    EXPECT_FLOAT_EQ(m.transmission, 0.7f);
    EXPECT_FLOAT_EQ(m.ior, 1.33f);
    expect_near(m.emissive, {4, 2, 0});
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].type, LightType::spot);
    EXPECT_FLOAT_EQ(s.lights[0].outer_cone, 0.5f);
    expect_near(s.lights[0].position, {0, 5, 0});
    expect_near(s.lights[0].direction, {0, -1, 0});
    expect_near(s.lights[0].color, {1, 0, 0});
    ASSERT_EQ(s.cameras.size(), 2u);
    expect_near(s.cameras[0].eye, {0, 0, 5});
    expect_near(s.cameras[0].forward, {0, 0, -1});
    expect_near(s.cameras[0].up, {0, 1, 0});
    EXPECT_FLOAT_EQ(s.cameras[0].yfov, 0.5f);
    ASSERT_EQ(s.warnings.size(), 1u);
    EXPECT_NE(s.warnings[0].find("orthographic"), std::string::npos);
}

TEST(GltfLoader, DefaultSceneFallsBackToRootNodes) {
    GltfBuilder b = test::one_triangle();
    b.doc.erase("scenes");
    b.doc.erase("scene");
    b.node({{"children", {2}}});
    b.node({{"mesh", 0}, {"translation", {0, 3, 0}}});
    Scene s = load_gltf(b.write(test::test_dir(), "roots"));
    EXPECT_EQ(s.instances.size(), 2u);  // roots 0 and 1; node 2 is a child
}

}  // namespace
}  // namespace rtsim
