// Malformed glTF: each gives rtsim::Error naming the file and the offending element, never a crash.
#include <fstream>

#include <gtest/gtest.h>

#include "tests/cpp/scene/gltf_builder.h"
#include "traces/common/error.h"
#include "traces/scene/gltf_loader.h"

namespace rtsim {
namespace {

using test::GltfBuilder;
using test::json;

using test::expect_error;

TEST(GltfErrors, MissingFile) {
    expect_error(test::test_dir() + "/no_such_scene.gltf", {"cannot open"});
}

TEST(GltfErrors, BadJson) {
    std::string path = test::test_dir() + "/broken.gltf";
    std::ofstream(path) << "{ \"asset\": { \"version\": \"2.0\" }, \"nodes\": [ {,, ";
    expect_error(path, {});
}

TEST(GltfErrors, TruncatedGlb) {
    std::string path = test::test_dir() + "/short.glb";
    std::ofstream(path, std::ios::binary) << "glTF\x02";
    expect_error(path, {});
}

TEST(GltfErrors, MissingBufferFile) {
    GltfBuilder b = test::one_triangle();
    std::string dir = test::test_dir();
    std::string path = b.write(dir, "nobuf", false);
    std::filesystem::remove(dir + "/nobuf.bin");
    expect_error(path, {"nobuf.bin"});
}

TEST(GltfErrors, AccessorOutOfRangeOfBufferView) {
    GltfBuilder b = test::one_triangle();
    b.doc["accessors"][0]["count"] = 1000;
    expect_error(b.write(test::test_dir(), "acc_range"),
                 {"mesh 0 'tri' primitive 0 POSITION", "accessor 0", "out of range of bufferView 0"});
}

TEST(GltfErrors, AccessorByteOffsetOverflow) {
    GltfBuilder b = test::one_triangle();
    b.doc["accessors"][0]["byteOffset"] = 4000000000u;
    expect_error(b.write(test::test_dir(), "acc_offset"), {"accessor 0", "out of range"});
}

TEST(GltfErrors, BufferViewOutOfRangeOfBuffer) {
    GltfBuilder b = test::one_triangle();
    b.doc["bufferViews"][0]["byteLength"] = 400;
    b.doc["bufferViews"][0]["byteOffset"] = 16;
    expect_error(b.write(test::test_dir(), "bv_range"), {"bufferView 0", "out of range of buffer 0"});
}

TEST(GltfErrors, BadBufferViewIndex) {
    GltfBuilder b = test::one_triangle();
    b.doc["accessors"][0]["bufferView"] = 9;
    expect_error(b.write(test::test_dir(), "bv_index"), {"accessor 0", "bufferView index 9 out of range"});
}

TEST(GltfErrors, IndexOutOfRange) {
    GltfBuilder b;
    int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
    int idx = b.indices(std::vector<uint32_t>{0, 1, 7});
    b.mesh("tri", {{{"attributes", {{"POSITION", pos}}}, {"indices", idx}}});
    b.node({{"mesh", 0}});
    b.scene({0});
    expect_error(b.write(test::test_dir(), "bad_index"),
                 {"mesh 0 'tri' primitive 0: index 7 out of range (vertex count 3)"});
}

TEST(GltfErrors, LinesAndPointsNeedRadii) {
    // LINES and POINTS are capsules and spheres, which need a radius per vertex.
    for (int mode : {0, 1, 2, 3}) {
        GltfBuilder b = test::one_triangle();
        b.doc["meshes"][0]["primitives"][0]["mode"] = mode;
        expect_error(b.write(test::test_dir(), "lines"), {"mesh 0 'tri' primitive 0", "need a _RADIUS attribute"});
    }
}

TEST(GltfErrors, PositionNotFloatVec3) {
    GltfBuilder b = test::one_triangle();
    b.doc["accessors"][0]["componentType"] = 5123;  // unsigned short
    expect_error(b.write(test::test_dir(), "quantized"), {"primitive 0", "POSITION must be float VEC3"});
}

TEST(GltfErrors, SparseAccessorRefused) {
    GltfBuilder b = test::one_triangle();
    b.doc["accessors"][0]["sparse"] = {{"count", 1},
                                       {"indices", {{"bufferView", 1}, {"componentType", 5123}}},
                                       {"values", {{"bufferView", 0}}}};
    expect_error(b.write(test::test_dir(), "sparse"), {"accessor 0", "sparse"});
}

TEST(GltfErrors, NodeCycle) {
    GltfBuilder b = test::one_triangle();
    b.doc["nodes"] = json::array();
    b.node({{"name", "a"}, {"children", {1}}});
    b.node({{"name", "b"}, {"children", {0}}, {"mesh", 0}});
    b.scene({0});
    expect_error(b.write(test::test_dir(), "cycle"), {"node 0 'a'", "cycle"});
}

TEST(GltfErrors, BadMeshIndexOnNode) {
    GltfBuilder b = test::one_triangle();
    b.doc["nodes"][0] = {{"name", "lamp"}, {"mesh", 5}};
    expect_error(b.write(test::test_dir(), "bad_mesh"), {"node 0 'lamp'", "mesh index 5 out of range"});
}

TEST(GltfErrors, BadChildIndex) {
    GltfBuilder b = test::one_triangle();
    b.doc["nodes"][0]["children"] = {42};
    expect_error(b.write(test::test_dir(), "bad_child"), {"node 0", "node index 42 out of range"});
}

TEST(GltfErrors, BadMaterialIndex) {
    GltfBuilder b = test::one_triangle();
    b.doc["meshes"][0]["primitives"][0]["material"] = 3;
    expect_error(b.write(test::test_dir(), "bad_mat"), {"primitive 0", "material index 3 out of range"});
}

TEST(GltfErrors, BadLightIndex) {
    GltfBuilder b = test::one_triangle();
    b.doc["nodes"][0]["extensions"] = {{"KHR_lights_punctual", {{"light", 2}}}};
    expect_error(b.write(test::test_dir(), "bad_light"), {"node 0", "light index 2 out of range"});
}

TEST(GltfErrors, RequiredDracoRefused) {
    GltfBuilder b = test::one_triangle();
    b.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
    b.doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
    expect_error(b.write(test::test_dir(), "draco"), {"KHR_draco_mesh_compression"});
}

}  // namespace
}  // namespace rtsim
