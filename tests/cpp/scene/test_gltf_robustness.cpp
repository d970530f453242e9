// Hostile glTF: inputs that crashed tinygltf, slipped through it, or cost memory
// without need. Each is refused with an Error naming the file and the element, or loads cheaply.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include <gtest/gtest.h>

#include "tests/cpp/scene/gltf_builder.h"
#include "traces/common/error.h"
#include "traces/scene/gltf_loader.h"

namespace rtsim {
namespace {

using test::expect_error;
using test::GltfBuilder;
using test::json;

/// The one-triangle document as a GLB (buffer 0 is the BIN chunk).
std::string one_triangle_glb(const std::string& dir, const std::string& name, json* edit_doc = nullptr,
                             uint32_t version = 2) {
    GltfBuilder b = test::one_triangle();
    json doc = b.doc;
    doc["buffers"] = json::array({{{"byteLength", b.bin.size()}}});
    if (edit_doc) doc.update(*edit_doc, true);
    return test::write_glb(dir + "/" + name + ".glb", doc, b.bin, version);
}

/// True if the text is well-formed UTF-8 (what Python needs to decode an error message).
bool is_utf8(const std::string& s) {
    for (size_t i = 0; i < s.size();) {
        const auto c = static_cast<unsigned char>(s[i]);
        const size_t len = c < 0x80 ? 1 : (c >> 5) == 6 ? 2 : (c >> 4) == 14 ? 3 : (c >> 3) == 30 ? 4 : 0;
        if (len == 0 || i + len > s.size()) return false;
        for (size_t k = 1; k < len; ++k)
            if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80) return false;
        i += len;
    }
    return true;
}

TEST(GltfRobustness, DeepJsonRefusedBeforeParsing) {
    std::string path = test::test_dir() + "/deep.gltf";
    std::ofstream(path) << R"({"asset":{"version":"2.0"},"extras":)" << std::string(20000, '[')
                        << std::string(20000, ']') << "}";
    expect_error(path, {"nested deeper than 512 levels"});
    // Brackets inside strings do not count.
    GltfBuilder b = test::one_triangle();
    b.doc["extras"] = {{"note", std::string(5000, '[')}};
    EXPECT_NO_THROW(load_gltf(b.write(test::test_dir(), "brackets_in_string")));
}

TEST(GltfRobustness, SceneIsAFolder) {
    std::string dir = test::test_dir() + "/scene.gltf";
    std::filesystem::create_directories(dir);
    expect_error(dir, {"is a folder"});
}

TEST(GltfRobustness, GlbVersionAndLength) {
    std::string dir = test::test_dir();
    EXPECT_NO_THROW(load_gltf(one_triangle_glb(dir, "ok")));
    expect_error(one_triangle_glb(dir, "v1", nullptr, 1), {"GLB container version 1"});
    std::string path = one_triangle_glb(dir, "long");
    std::ofstream(path, std::ios::binary | std::ios::app) << "trailing";
    expect_error(path, {"GLB header says"});
}

TEST(GltfRobustness, GlbBufferByteLengthZero) {
    json edit = {{"buffers", json::array({{{"byteLength", 0}}})}};
    expect_error(one_triangle_glb(test::test_dir(), "len0", &edit), {"buffer 0", "byteLength is 0"});
}

TEST(GltfRobustness, NegativeOffsetsAndStrides) {
    const std::string dir = test::test_dir();
    GltfBuilder b = test::one_triangle();
    b.doc["bufferViews"][0]["byteOffset"] = -8;
    expect_error(b.write(dir, "neg_view_offset"), {"bufferView 0", "byteOffset is -8"});
    b = test::one_triangle();
    b.doc["bufferViews"][0]["byteStride"] = -12;
    expect_error(b.write(dir, "neg_stride"), {"bufferView 0", "byteStride is -12"});
    b = test::one_triangle();
    b.doc["accessors"][1]["byteOffset"] = -2;
    expect_error(b.write(dir, "neg_acc_offset"), {"accessor 1", "byteOffset is -2"});
    b = test::one_triangle();
    b.doc["accessors"][0]["count"] = 1.5;
    expect_error(b.write(dir, "frac_count"), {"accessor 0", "count is 1.5"});
}

TEST(GltfRobustness, TextureIndicesInRange) {
    const std::string dir = test::test_dir();
    GltfBuilder b = test::one_triangle();
    b.doc["materials"] = {{{"name", "paint"}, {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 7}}}}}}};
    b.doc["meshes"][0]["primitives"][0]["material"] = 0;
    expect_error(b.write(dir, "tex_core"),
                 {"material 0 'paint'.pbrMetallicRoughness.baseColorTexture", "texture index 7 out of range (0 textures)"});
    b.doc["materials"][0] = {{"extensions", {{"KHR_materials_transmission", {{"transmissionTexture", {{"index", -1}}}}}}}};
    expect_error(b.write(dir, "tex_ext"), {"transmissionTexture", "texture index -1 out of range"});
    b.doc["materials"][0] = {{"normalTexture", {{"index", 0}}}};
    b.doc["textures"] = {{{"source", 3}}};
    expect_error(b.write(dir, "tex_source"), {"texture 0", "source: image index 3 out of range (0 images)"});
}

TEST(GltfRobustness, ImagesAreNotDecoded) {
    // An image whose bytes no decoder accepts: only a loader that decodes images would fail.
    GltfBuilder b = test::one_triangle();
    b.doc["images"] = {{{"uri", "data:image/png;base64," + test::base64({1, 2, 3, 4, 5, 6, 7, 8})}}};
    b.doc["textures"] = {{{"source", 0}}};
    b.doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
    b.doc["meshes"][0]["primitives"][0]["material"] = 0;
    Scene scene = load_gltf(b.write(test::test_dir(), "undecodable_image"));
    EXPECT_EQ(scene.triangle_count(), 1u);
}

TEST(GltfRobustness, NonUtf8BytesInTheMessageAreEscaped) {
    std::string path = test::test_dir() + "/latin1.gltf";
    std::ofstream(path, std::ios::binary) << "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"name\":\"caf\xe9\xff\"}]}";
    std::string msg = expect_error(path, {});
    EXPECT_TRUE(is_utf8(msg)) << msg;
}

TEST(GltfRobustness, NoTrianglesNamesTheFile) {
    GltfBuilder b = test::one_triangle();
    b.doc["nodes"][0].erase("mesh");
    expect_error(b.write(test::test_dir(), "empty_scene"), {"the scene has no triangles"});
}

TEST(GltfRobustness, NonFiniteVertexNamesTheFileAndMesh) {
    const std::string dir = test::test_dir();
    GltfBuilder b;
    const float inf = std::numeric_limits<float>::infinity();
    b.positions({0, 0, 0, inf, 0, 0, 0, 1, 0});
    b.mesh("spiky", {{{"attributes", {{"POSITION", 0}}}}});
    b.node({{"mesh", 0}});
    b.scene({0});
    expect_error(b.write(dir, "inf_vertex"), {"mesh 0 'spiky' triangle 0", "non-finite vertex"});
    // Finite in the file, beyond the float range once placed by its node.
    b = test::one_triangle();
    b.doc["nodes"][0]["scale"] = {1e300, 1, 1};
    expect_error(b.write(dir, "huge_node"), {"mesh 0 'tri' triangle 0 placed by node 0", "non-finite vertex"});
}

TEST(GltfRobustness, InstancingBlowUpRefusedWithTheFigure) {
    // 200,000 EXT_mesh_gpu_instancing copies of a 20,000-triangle mesh: 4e9 triangles, more
    // than any machine's limit (int32 primitive ids), refused before anything is expanded.
    GltfBuilder b;
    int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
    std::vector<uint16_t> idx;
    for (int t = 0; t < 20000; ++t) idx.insert(idx.end(), {0, 1, 2});
    int ind = b.indices(idx);
    std::vector<float> translations(3 * 200000, 0.0f);
    int tr = b.accessor(b.view(translations.data(), translations.size() * 4), 5126, "VEC3", 200000);
    b.mesh("grass", {{{"attributes", {{"POSITION", pos}}}, {"indices", ind}}});
    b.node({{"name", "field"},
            {"mesh", 0},
            {"extensions", {{"EXT_mesh_gpu_instancing", {{"attributes", {{"TRANSLATION", tr}}}}}}}});
    b.scene({0});
    b.doc["extensionsUsed"] = {"EXT_mesh_gpu_instancing"};
    expect_error(b.write(test::test_dir(), "blowup"),
                 {"node 0 'field' EXT_mesh_gpu_instancing", "200000 instances of 20000 triangles",
                  "flattens to 4000000000 triangles", "GiB"});
}

}  // namespace
}  // namespace rtsim
