#pragma once
// Tiny hand-written glTF files for the loader tests: JSON built with nlohmann::json, buffer either
// embedded as a base64 data URI or written as an external .bin next to the .gltf.
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "traces/common/error.h"
#include "traces/scene/gltf_loader.h"

namespace rtsim::test {

using nlohmann::json;

/// A fresh, empty directory per test (under GoogleTest's temp dir).
inline std::string test_dir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "rtsim_scene_tests" /
                                (std::string(info->test_suite_name()) + "." + info->name());
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir.string();
}

inline std::string base64(const std::vector<uint8_t>& data) {
    static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < data.size(); i += 3) {
        uint32_t v = uint32_t(data[i]) << 16;
        if (i + 1 < data.size()) v |= uint32_t(data[i + 1]) << 8;
        if (i + 2 < data.size()) v |= data[i + 2];
        out += t[(v >> 18) & 63];
        out += t[(v >> 12) & 63];
        out += i + 1 < data.size() ? t[(v >> 6) & 63] : '=';
        out += i + 2 < data.size() ? t[v & 63] : '=';
    }
    return out;
}

/// Builds a glTF document piece by piece.
struct GltfBuilder {
    json doc = {{"asset", {{"version", "2.0"}}}};
    std::vector<uint8_t> bin;

    /// Appends raw bytes as a bufferView; returns its index.
    int view(const void* data, size_t bytes) {
        while (bin.size() % 4) bin.push_back(0);
        size_t offset = bin.size();
        bin.resize(offset + bytes);
        std::memcpy(bin.data() + offset, data, bytes);
        doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}});
        return int(doc["bufferViews"].size() - 1);
    }
    int accessor(int view, int component_type, const char* type, size_t count) {
        doc["accessors"].push_back(
            {{"bufferView", view}, {"componentType", component_type}, {"type", type}, {"count", count}});
        return int(doc["accessors"].size() - 1);
    }
    int positions(const std::vector<float>& xyz) {
        return accessor(view(xyz.data(), xyz.size() * 4), 5126, "VEC3", xyz.size() / 3);
    }
    template <typename T>
    int indices(const std::vector<T>& idx) {
        int ct = sizeof(T) == 1 ? 5121 : sizeof(T) == 2 ? 5123 : 5125;
        return accessor(view(idx.data(), idx.size() * sizeof(T)), ct, "SCALAR", idx.size());
    }
    /// Adds a mesh; each primitive is a JSON object (attributes, indices, mode, material).
    int mesh(const std::string& name, const std::vector<json>& primitives) {
        doc["meshes"].push_back({{"name", name}, {"primitives", primitives}});
        return int(doc["meshes"].size() - 1);
    }
    int node(json n) {
        doc["nodes"].push_back(std::move(n));
        return int(doc["nodes"].size() - 1);
    }
    void scene(const std::vector<int>& roots) {
        doc["scenes"] = json::array({{{"nodes", roots}}});
        doc["scene"] = 0;
    }
    /// Writes `<dir>/<name>.gltf` (and `<name>.bin` unless embedded); returns the .gltf path.
    std::string write(const std::string& dir, const std::string& name, bool embed = true) {
        json d = doc;
        if (!bin.empty()) {
            std::string uri = embed ? "data:application/octet-stream;base64," + base64(bin) : name + ".bin";
            d["buffers"] = json::array({{{"byteLength", bin.size()}, {"uri", uri}}});
            if (!embed) {
                std::ofstream(dir + "/" + name + ".bin", std::ios::binary)
                    .write(reinterpret_cast<const char*>(bin.data()), std::streamsize(bin.size()));
            }
        }
        std::string path = dir + "/" + name + ".gltf";
        std::ofstream(path) << d.dump(1);
        return path;
    }
};

/// Loads `path`, expecting an Error whose message contains the file name and every fragment;
/// returns the message ("" if it loaded).
inline std::string expect_error(const std::string& path, const std::vector<std::string>& fragments) {
    std::string file = std::filesystem::path(path).filename().string();
    try {
        load_gltf(path);
        ADD_FAILURE() << path << ": loaded without error";
    } catch (const Error& e) {
        std::string msg = e.what();
        EXPECT_NE(msg.find(file), std::string::npos) << "message lacks the file name: " << msg;
        for (const std::string& f : fragments)
            EXPECT_NE(msg.find(f), std::string::npos) << "message lacks '" << f << "': " << msg;
        return msg;
    }
    return "";
}

/// Writes a GLB container: 12-byte header, JSON chunk (space-padded), BIN chunk (zero-padded,
/// omitted when empty). `version` goes into the header as is.
inline std::string write_glb(const std::string& path, const json& doc, std::vector<uint8_t> bin,
                             uint32_t version = 2) {
    std::string text = doc.dump();
    while (text.size() % 4) text += ' ';
    while (bin.size() % 4) bin.push_back(0);
    std::string out;
    auto u32 = [&out](uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
    const uint32_t total = uint32_t(12 + 8 + text.size() + (bin.empty() ? 0 : 8 + bin.size()));
    u32(0x46546C67u);
    u32(version);
    u32(total);
    u32(uint32_t(text.size()));
    u32(0x4E4F534Au);
    out += text;
    if (!bin.empty()) {
        u32(uint32_t(bin.size()));
        u32(0x004E4942u);
        out.append(reinterpret_cast<const char*>(bin.data()), bin.size());
    }
    std::ofstream(path, std::ios::binary) << out;
    return path;
}

/// A one-triangle mesh (0,0,0), (1,0,0), (0,1,0) named "tri" with u16 indices, node 0, scene 0.
inline GltfBuilder one_triangle() {
    GltfBuilder b;
    int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
    int idx = b.indices(std::vector<uint16_t>{0, 1, 2});
    b.mesh("tri", {{{"attributes", {{"POSITION", pos}}}, {"indices", idx}}});
    b.node({{"mesh", 0}});
    b.scene({0});
    return b;
}

}  // namespace rtsim::test
