#pragma once
// Internals of the glTF loader shared by gltf_loader.cpp, gltf_accessor.cpp, gltf_geometry.cpp and
// gltf_materials.cpp. Not part of the public interface: include only from traces/scene/*.cpp.
#include <cstddef>
#include <cstdint>
#include <string>

#include <tiny_gltf.h>

#include "traces/common/error.h"
#include "traces/scene/scene.h"

namespace rtsim::gltf {

/// The model being read and the file it came from; every error message starts with `file`.
struct Source {
    std::string file;
    const tinygltf::Model* model = nullptr;
    bool flatten = true;  ///< the scene will be flattened (its size is checked against memory)

    /// Throws rtsim::Error("<file>: <what>").
    [[noreturn]] void fail(const std::string& what) const;
};

/// "mesh 0 'sponza'", "node 3", ...: an element named by index and, if it has one, name.
std::string element(const char* kind, size_t index, const std::string& name = "");

/// A bounds-checked window on one accessor's bytes (never sparse, always backed by a buffer).
struct AccessorView {
    const unsigned char* data = nullptr;
    size_t count = 0;
    size_t stride = 0;
    int component_type = 0;
    int components = 0;
    bool normalized = false;

    /// Component c of element i as a float (normalised integers mapped to [0,1] or [-1,1]).
    float component(size_t i, int c) const;
    /// Element i of a SCALAR unsigned-integer accessor.
    uint32_t index(size_t i) const;
};

/// Checks accessor `index` (range, bufferView, buffer, byteOffset + stride * count bounds, sparse)
/// and returns its view. `where` names the user, e.g. "mesh 0 'a' primitive 1 POSITION".
AccessorView view_accessor(const Source& src, int index, const std::string& where);

/// Appends glTF mesh `mesh_index` to scene.meshes (all triangle primitives, strips and fans
/// converted to lists) and returns its index in scene.meshes.
uint32_t read_mesh(const Source& src, int mesh_index, Scene& scene);

/// The vertex index of each triangle corner of a triangle primitive, in the order read_mesh
/// appends them to Mesh::positions (strips and fans converted). The animation reads skin
/// weights and morph deltas per corner through it.
std::vector<uint32_t> primitive_corners(const Source& src, const tinygltf::Primitive& prim,
                                        size_t vertex_count, const std::string& where);

/// Reads every glTF material into scene.materials, in order (glTF index == rtsim index).
void read_materials(const Source& src, Scene& scene);

/// Light `light_index` placed by a node's world matrix.
Light read_light(const Source& src, int light_index, const glm::dmat4& world, int node);
/// Camera `camera_index` placed by a node's world matrix; orthographic cameras warn.
Camera read_camera(const Source& src, int camera_index, const glm::dmat4& world, int node,
                   Scene& scene);

/// Deepest JSON nesting a glTF file may have. tinygltf recurses once per level; real files
/// nest a handful of levels (extras and extensions included), so 512 leaves ample room.
constexpr size_t kMaxJsonDepth = 512;

/// Refuses JSON text nested deeper than kMaxJsonDepth (one linear scan, before any parsing).
void check_json_depth(const std::string& file, const unsigned char* text, size_t size);
/// Checks every integer field of the glTF 2.0 schema by value (gltf_json_schema.cpp): an
/// integer-valued number (3.0) is that integer, a fractional, non-numeric or out-of-range one
/// is refused naming the element and key; every index is checked against its array, node
/// transforms are arrays of finite numbers, bufferViews lie inside their buffers. Returns the
/// document re-serialised when a number was rewritten (tinygltf drops 3.0 silently), else "".
/// Text that is not a JSON object is left for tinygltf to report.
std::string normalize_document(const std::string& file, const unsigned char* text, size_t size);

/// The JSON chunk of a GLB file.
struct GlbChunks {
    const unsigned char* json = nullptr;
    size_t json_bytes = 0;
};
/// Validates a GLB header (version 2, length, first chunk JSON) and returns its JSON chunk.
GlbChunks check_glb(const std::string& file, const unsigned char* data, size_t size);

/// The text with every byte that is not part of well-formed UTF-8 written as "\xNN", so an
/// error message can always be shown (and decoded by Python).
std::string valid_utf8(const std::string& text);

/// Number `key` of a JSON object value, or `fallback` when absent or not a number.
double value_number(const tinygltf::Value& object, const char* key, double fallback);
/// A JSON number as an element index, -1 when it is not a non-negative integer that fits an int.
int as_index(double number);

}  // namespace rtsim::gltf
