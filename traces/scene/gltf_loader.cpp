// load_gltf: reads the file through tinygltf, walks the default scene's node hierarchy in double
// precision and turns meshes, EXT_mesh_gpu_instancing entries, lights and cameras into a Scene.
#include "traces/scene/gltf_loader.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "traces/common/files.h"
#include "traces/scene/gltf_animation.h"
#include "traces/scene/gltf_internal.h"
#include "traces/scene/procedural_motion.h"

namespace rtsim {

namespace {

namespace fs = std::filesystem;
using gltf::element;
using gltf::Source;

/// Extensions whose meaning rtsim reads or which cannot change the geometry.
bool extension_supported(const std::string& name) {
    static const std::set<std::string> kGeometry = {"EXT_mesh_gpu_instancing", "KHR_lights_punctual",
                                                    "KHR_texture_transform", "KHR_materials_variants"};
    return kGeometry.count(name) || name.rfind("KHR_materials_", 0) == 0;
}

/// The whole file; a folder, a FIFO or device, an unreadable or a > 4 GiB file (tinygltf's limit) is refused.
std::vector<unsigned char> read_file(const std::string& path) {
    require_regular_file(path, "glTF file (.gltf or .glb)");
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in) throw Error(path + ": cannot open file");
    const std::streamoff size = in.tellg();
    if (size < 0) throw Error(path + ": cannot read file");
    if (uint64_t(size) >= (uint64_t(1) << 32))
        throw Error(path + ": " + std::to_string(size) + " bytes; glTF files of 4 GiB or more are not supported");
    std::vector<unsigned char> bytes(static_cast<size_t>(size));
    in.seekg(0);
    if (!in.read(reinterpret_cast<char*>(bytes.data()), size)) throw Error(path + ": cannot read file");
    return bytes;
}

/// Width and height from a PNG (IHDR) or JPEG (first SOFn marker) header; false for other data.
bool image_header_size(const unsigned char* d, int size, int* w, int* h) {
    const auto be16 = [d](int i) { return int(d[i]) << 8 | int(d[i + 1]); };
    if (size >= 24 && d[0] == 0x89 && d[1] == 'P' && d[2] == 'N' && d[3] == 'G') {
        *w = be16(16) << 16 | be16(18);
        *h = be16(20) << 16 | be16(22);
        return true;
    }
    if (size < 4 || d[0] != 0xFF || d[1] != 0xD8) return false;
    for (int i = 2; i + 9 < size;) {
        if (d[i] != 0xFF) return false;
        const int marker = d[i + 1], length = be16(i + 2);
        const bool sof = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
        if (sof) {
            *h = be16(i + 5);
            *w = be16(i + 7);
            return true;
        }
        i += 2 + length;
    }
    return false;
}

/// tinygltf image callback that decodes nothing: rtsim needs only each image's size (the shader
/// model's texture footprint; alpha coverage comes from extras.textureAlphaCoverage), read from
/// its header, so an 8000 x 8000 PNG never costs 256 MB.
bool skip_image(tinygltf::Image* image, const int, std::string*, std::string*, int, int, const unsigned char* bytes,
                int size, void*) {
    int w = 0, h = 0;
    if (bytes && image_header_size(bytes, size, &w, &h)) {
        image->width = w;
        image->height = h;
    }
    return true;
}

/// The file's bytes with its JSON replaced by `text` (a new GLB container around the same
/// binary chunk when the file is a GLB).
std::vector<unsigned char> with_json(const std::vector<unsigned char>& bytes, bool binary,
                                     const gltf::GlbChunks& old, std::string text) {
    if (!binary) return std::vector<unsigned char>(text.begin(), text.end());
    text.append((4 - text.size() % 4) % 4, ' ');
    const size_t rest = size_t(old.json - bytes.data()) + old.json_bytes;  // the chunks after JSON
    const size_t total = 20 + text.size() + (bytes.size() - rest);
    if (total >= (uint64_t(1) << 32)) throw Error("GLB grows beyond 4 GiB");
    std::vector<unsigned char> out(20);
    auto put32 = [&out](size_t at, uint32_t v) {
        for (int i = 0; i < 4; ++i) out[at + size_t(i)] = static_cast<unsigned char>(v >> (8 * i));
    };
    std::memcpy(out.data(), bytes.data(), 8);  // magic and version
    put32(8, uint32_t(total));
    put32(12, uint32_t(text.size()));
    put32(16, 0x4E4F534Au);  // "JSON"
    out.insert(out.end(), text.begin(), text.end());
    out.insert(out.end(), bytes.begin() + std::ptrdiff_t(rest), bytes.end());
    return out;
}

/// Loads the model (binary if the file starts with the GLB magic) or throws naming the file.
/// The raw bytes are checked first (gltf_json_checks.cpp, gltf_json_schema.cpp): nesting depth,
/// GLB header, every integer and index by value, which tinygltf would crash on or drop.
void load_model(const std::string& path, tinygltf::Model& model, Scene& scene) {
    std::vector<unsigned char> bytes = read_file(path);
    const bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
    gltf::GlbChunks json{bytes.data(), bytes.size()};
    if (binary) json = gltf::check_glb(path, bytes.data(), bytes.size());
    gltf::check_json_depth(path, json.json, json.json_bytes);
    const std::string normalized = gltf::normalize_document(path, json.json, json.json_bytes);
    if (!normalized.empty()) bytes = with_json(bytes, binary, json, normalized);

    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(&skip_image, nullptr);
    const std::string base = fs::path(path).parent_path().string();
    const auto size = static_cast<unsigned int>(bytes.size());
    std::string err, warn;
    bool ok = false;
    try {
        ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), size, base)
                    : loader.LoadASCIIFromString(&model, &err, &warn, reinterpret_cast<const char*>(bytes.data()),
                                                 size, base);
    } catch (const std::bad_alloc&) {
        throw Error(path + ": out of memory while parsing the file");
    } catch (const std::exception& e) {  // tinygltf's .at() and JSON conversions
        throw Error(path + ": malformed glTF (" + e.what() + ")");
    }
    if (!ok || !err.empty()) {
        while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
        throw Error(path + ": " + (err.empty() ? std::string("tinygltf failed to load the file") : err));
    }
    if (!warn.empty()) scene.warnings.push_back(gltf::valid_utf8(warn));
    for (const std::string& ext : model.extensionsRequired)
        if (!extension_supported(ext)) throw Error(path + ": required extension " + ext + " is not supported");
}

/// A node's local matrix: `matrix` if present, else T * R * S (glTF 2.0 section 3.5.3).
glm::dmat4 local_matrix(const Source& src, const tinygltf::Node& node, size_t index) {
    std::string where = element("node", index, node.name);
    if (!node.matrix.empty()) {
        if (node.matrix.size() != 16) src.fail(where + ": matrix must have 16 numbers");
        glm::dmat4 m;
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) m[c][r] = node.matrix[size_t(4 * c + r)];  // column-major
        return m;
    }
    glm::dmat4 t(1.0), r(1.0), s(1.0);
    if (!node.translation.empty()) {
        if (node.translation.size() != 3) src.fail(where + ": translation must have 3 numbers");
        t[3] = glm::dvec4(node.translation[0], node.translation[1], node.translation[2], 1.0);
    }
    if (!node.rotation.empty()) {
        if (node.rotation.size() != 4) src.fail(where + ": rotation must have 4 numbers");
        const auto& q = node.rotation;  // glTF order x, y, z, w
        r = glm::mat4_cast(glm::normalize(glm::dquat(q[3], q[0], q[1], q[2])));
    }
    if (!node.scale.empty()) {
        if (node.scale.size() != 3) src.fail(where + ": scale must have 3 numbers");
        s = glm::scale(glm::dmat4(1.0), glm::dvec3(node.scale[0], node.scale[1], node.scale[2]));
    }
    return t * r * s;
}

/// Checks the triangles placed so far: against memory when the scene will be flattened
/// (check_flat_size), else against the int32 primitive ids of a two-level scene.
void check_placed(const Source& src, uint64_t placed, const std::string& what) {
    if (src.flatten) {
        check_flat_size(src.file, placed, what);
        return;
    }
    if (placed > uint64_t(INT32_MAX))
        src.fail(what + " places " + std::to_string(placed) + " triangles; primitive ids are int32");
}

/// Instance transforms of an EXT_mesh_gpu_instancing node: world x T_i x R_i x S_i.
/// `flat` counts the scene's triangles so far (each instance counts at least one): the
/// flattened size is checked before the instances are expanded.
std::vector<glm::dmat4> gpu_instances(const Source& src, const tinygltf::Value& ext, size_t node,
                                      const glm::dmat4& world, uint64_t mesh_triangles, uint64_t* flat) {
    std::string where = element("node", node, src.model->nodes[node].name) + " EXT_mesh_gpu_instancing";
    const tinygltf::Value& attrs = ext.IsObject() ? ext.Get("attributes") : ext;
    if (!attrs.IsObject()) src.fail(where + ": no attributes object");
    const char* names[3] = {"TRANSLATION", "ROTATION", "SCALE"};
    const int sizes[3] = {3, 4, 3};
    gltf::AccessorView views[3];
    bool present[3] = {false, false, false};
    size_t count = 0;
    bool have_count = false;
    for (int a = 0; a < 3; ++a) {
        if (!attrs.Has(names[a])) continue;
        const tinygltf::Value& v = attrs.Get(names[a]);
        if (!v.IsNumber()) src.fail(where + ": " + names[a] + " is not an accessor index");
        views[a] = gltf::view_accessor(src, gltf::as_index(v.GetNumberAsDouble()), where + " " + names[a]);
        if (views[a].components != sizes[a]) src.fail(where + ": " + names[a] + " has the wrong type");
        // EXT_mesh_gpu_instancing: TRANSLATION and SCALE are floats; ROTATION floats or
        // normalised signed bytes or shorts.
        const int type = views[a].component_type;
        const bool ok = type == TINYGLTF_COMPONENT_TYPE_FLOAT ||
                        (a == 1 && views[a].normalized &&
                         (type == TINYGLTF_COMPONENT_TYPE_BYTE || type == TINYGLTF_COMPONENT_TYPE_SHORT));
        if (!ok)
            src.fail(where + ": " + names[a] + " has componentType " + std::to_string(type) +
                     (a == 1 ? " (must be 5126 float, or normalized 5120 byte or 5122 short)"
                             : " (must be 5126 float)"));
        if (have_count && views[a].count != count) src.fail(where + ": attribute counts differ");
        count = views[a].count;
        have_count = present[a] = true;
    }
    if (!have_count) src.fail(where + ": no TRANSLATION, ROTATION or SCALE attribute");
    *flat += uint64_t(count) * std::max<uint64_t>(mesh_triangles, 1);
    check_placed(src, *flat, where + " (" + std::to_string(count) + " instances of " +
                                 std::to_string(mesh_triangles) + " triangles, with the nodes before it)");
    std::vector<glm::dmat4> out(count);
    for (size_t i = 0; i < count; ++i) {
        glm::dmat4 t(1.0), r(1.0), s(1.0);
        auto comp = [&](int a, int c) { return double(views[a].component(i, c)); };
        if (present[0]) t[3] = glm::dvec4(comp(0, 0), comp(0, 1), comp(0, 2), 1.0);
        if (present[1]) r = glm::mat4_cast(glm::normalize(glm::dquat(comp(1, 3), comp(1, 0), comp(1, 1), comp(1, 2))));
        if (present[2]) s = glm::scale(glm::dmat4(1.0), glm::dvec3(comp(2, 0), comp(2, 1), comp(2, 2)));
        out[i] = world * t * r * s;
    }
    return out;
}

/// Depth-first walk of the scene's nodes (order documented in scene.h).
class NodeWalker {
public:
    NodeWalker(const Source& src, Scene& scene)
        : m_src(src), m_scene(scene), m_state(src.model->nodes.size(), 0),
          m_mesh_of(src.model->meshes.size(), -1) {}

    /// glTF mesh index -> Scene::meshes index (-1: not placed by the default scene).
    const std::vector<int>& mesh_of() const { return m_mesh_of; }

    void walk_root(int node) {
        check_index(node, "scene root");
        // Explicit stack: deep hierarchies cannot overflow the call stack.
        struct Frame {
            size_t node;
            glm::dmat4 world;
            size_t next_child;
        };
        std::vector<Frame> stack;
        stack.push_back({size_t(node), enter(size_t(node), glm::dmat4(1.0)), 0});
        while (!stack.empty()) {
            Frame& f = stack.back();
            const tinygltf::Node& gn = m_src.model->nodes[f.node];
            if (f.next_child == gn.children.size()) {
                m_state[f.node] = 2;
                stack.pop_back();
                continue;
            }
            int child = gn.children[f.next_child++];
            check_index(child, element("node", f.node, gn.name) + " child");
            glm::dmat4 world = f.world;  // copy: push_back may move the frame
            stack.push_back({size_t(child), enter(size_t(child), world), 0});
        }
    }

private:
    void check_index(int node, const std::string& where) {
        if (node < 0 || size_t(node) >= m_state.size())
            m_src.fail(where + ": node index " + std::to_string(node) + " out of range (" +
                       std::to_string(m_state.size()) + " nodes)");
    }

    /// Marks the node visited, emits what it carries and returns its world matrix.
    glm::dmat4 enter(size_t index, const glm::dmat4& parent) {
        const tinygltf::Node& node = m_src.model->nodes[index];
        std::string where = element("node", index, node.name);
        if (m_state[index] == 1) m_src.fail(where + ": node cycle (the node is its own ancestor)");
        if (m_state[index] == 2) m_src.fail(where + ": reached twice (a node may have only one parent)");
        m_state[index] = 1;
        glm::dmat4 world = parent * local_matrix(m_src, node, index);
        if (node.mesh >= 0 || node.mesh < -1) emit_mesh(index, world);
        auto light = node.extensions.find("KHR_lights_punctual");
        if (light != node.extensions.end())
            m_scene.lights.push_back(gltf::read_light(
                m_src, gltf::as_index(gltf::value_number(light->second, "light", -1.0)), world, int(index)));
        if (node.camera >= 0)
            m_scene.cameras.push_back(gltf::read_camera(m_src, node.camera, world, int(index), m_scene));
        return world;
    }

    void emit_mesh(size_t index, const glm::dmat4& world) {
        const tinygltf::Node& node = m_src.model->nodes[index];
        if (node.mesh < 0 || size_t(node.mesh) >= m_mesh_of.size())
            m_src.fail(element("node", index, node.name) + ": mesh index " + std::to_string(node.mesh) +
                       " out of range (" + std::to_string(m_mesh_of.size()) + " meshes)");
        // One rtsim::Mesh per glTF mesh, however many nodes use it.
        int& mesh = m_mesh_of[size_t(node.mesh)];
        if (mesh < 0) mesh = int(gltf::read_mesh(m_src, node.mesh, m_scene));
        auto inst = node.extensions.find("EXT_mesh_gpu_instancing");
        const uint64_t triangles = m_scene.meshes[size_t(mesh)].triangle_count();
        if (inst == node.extensions.end()) {
            m_flat += std::max<uint64_t>(triangles, 1);
            check_placed(m_src, m_flat, element("node", index, node.name) + " (with the nodes before it)");
            m_scene.instances.push_back({uint32_t(mesh), world, 0, int32_t(index)});
            return;
        }
        for (const glm::dmat4& m : gpu_instances(m_src, inst->second, index, world, triangles, &m_flat))
            m_scene.instances.push_back({uint32_t(mesh), m, 0, int32_t(index)});
    }

    const Source& m_src;
    Scene& m_scene;
    std::vector<uint8_t> m_state;  ///< 0 unvisited, 1 on the current path, 2 done
    std::vector<int> m_mesh_of;    ///< glTF mesh index -> Scene::meshes index (-1 not read yet)
    uint64_t m_flat = 0;           ///< triangles placed so far (at least one per instance)
};

/// Meshes the project's own procedural scenes mark as deforming (extras.rtsimMotion) become
/// Scene::animation.
void read_motions(const Source& src, const std::vector<int>& mesh_of, Scene& scene) {
    std::vector<std::pair<uint32_t, ProceduralMotion>> motions;
    for (size_t i = 0; i < mesh_of.size(); ++i) {
        ProceduralMotion motion;
        const tinygltf::Mesh& mesh = src.model->meshes[i];
        if (mesh_of[i] >= 0 &&
            read_procedural_motion(mesh.extras, src.file + ": " + element("mesh", i, mesh.name), &motion))
            motions.emplace_back(uint32_t(mesh_of[i]), motion);
    }
    if (!motions.empty()) scene.animation = make_procedural_animation(scene, std::move(motions));
    else scene.animation = gltf::read_gltf_animation(src, mesh_of, scene);
}

Scene load_gltf_checked(const std::string& path, bool flatten) {
    Scene scene;
    scene.source = path;
    tinygltf::Model model;
    load_model(path, model, scene);
    Source src{path, &model, flatten};
    gltf::read_materials(src, scene);

    // Default scene: model.defaultScene, else scene 0, else every root node.
    std::vector<int> roots;
    if (!model.scenes.empty()) {
        int s = model.defaultScene >= 0 ? model.defaultScene : 0;
        if (size_t(s) >= model.scenes.size())
            src.fail("default scene " + std::to_string(s) + " out of range (" +
                     std::to_string(model.scenes.size()) + " scenes)");
        roots = model.scenes[size_t(s)].nodes;
    } else {
        std::vector<bool> is_child(model.nodes.size(), false);
        for (const auto& n : model.nodes)
            for (int c : n.children)
                if (c >= 0 && size_t(c) < model.nodes.size()) is_child[size_t(c)] = true;
        for (size_t i = 0; i < model.nodes.size(); ++i)
            if (!is_child[i]) roots.push_back(int(i));
    }
    NodeWalker walker(src, scene);
    for (int r : roots) walker.walk_root(r);

    if (scene.materials.empty()) scene.default_material();
    read_motions(src, walker.mesh_of(), scene);
    check_instance_transforms(scene, false);
    if (flatten) scene.flatten();
    else scene.index_instances();
    if (scene.triangle_count() == 0)
        throw Error(path + ": the scene has no triangles (no mesh with TRIANGLES, TRIANGLE_STRIP or "
                           "TRIANGLE_FAN primitives in its default scene)");
    return scene;
}

}  // namespace

Scene load_gltf(const std::string& path, bool flatten) {
    try {
        return load_gltf_checked(path, flatten);
    } catch (const Error& e) {
        // Names and tinygltf's messages may quote bytes that are not UTF-8 (a Python caller
        // decodes the message): escape them rather than lose the message.
        throw Error(gltf::valid_utf8(e.what()));
    }
}

}  // namespace rtsim
