// glTF meshes to rtsim::Mesh: every primitive's triangles, in primitive order, as a triangle list;
// POINTS primitives with a _RADIUS attribute as spheres.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "traces/scene/gltf_internal.h"

namespace rtsim::gltf {

namespace {

const char* mode_name(int mode) {
    switch (mode) {
        case TINYGLTF_MODE_POINTS: return "POINTS";
        case TINYGLTF_MODE_LINE: return "LINES";
        case TINYGLTF_MODE_LINE_LOOP: return "LINE_LOOP";
        case TINYGLTF_MODE_LINE_STRIP: return "LINE_STRIP";
        case TINYGLTF_MODE_TRIANGLES: return "TRIANGLES";
        case TINYGLTF_MODE_TRIANGLE_STRIP: return "TRIANGLE_STRIP";
        case TINYGLTF_MODE_TRIANGLE_FAN: return "TRIANGLE_FAN";
        default: return "unknown";
    }
}

bool is_line_mode(int mode) {
    return mode == TINYGLTF_MODE_LINE || mode == TINYGLTF_MODE_LINE_LOOP || mode == TINYGLTF_MODE_LINE_STRIP;
}

/// Vertex indices of a primitive as a triangle list. Strips and fans follow the glTF 2.0 spec
/// (section 3.7.2.1) so that every triangle keeps the winding of the first one:
/// strip triangle i = {i, i + 1 + i%2, i + 2 - i%2}; fan triangle i = {i + 1, i + 2, 0}.
std::vector<uint32_t> triangle_list(const std::vector<uint32_t>& idx, int mode) {
    std::vector<uint32_t> out;
    size_t n = idx.size();
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        out.assign(idx.begin(), idx.begin() + (n / 3) * 3);
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP && n >= 3) {
        out.reserve(3 * (n - 2));
        for (size_t i = 0; i + 2 < n; ++i) {
            size_t odd = i % 2;
            out.insert(out.end(), {idx[i], idx[i + 1 + odd], idx[i + 2 - odd]});
        }
    } else if (mode == TINYGLTF_MODE_TRIANGLE_FAN && n >= 3) {
        out.reserve(3 * (n - 2));
        for (size_t i = 0; i + 2 < n; ++i) out.insert(out.end(), {idx[i + 1], idx[i + 2], idx[0]});
    } else if (mode == TINYGLTF_MODE_POINTS) {
        // Spheres: a primitive's three corners are its centre (scene.h, Mesh::radii).
        out.reserve(3 * n);
        for (uint32_t i : idx) out.insert(out.end(), {i, i, i});
    } else if (is_line_mode(mode) && n >= 2) {
        // Capsules: a segment's corners are its two ends and the second again (glTF 2.0
        // section 3.7.2.1's segments: pairs for LINES, consecutive for LINE_STRIP, closed for
        // LINE_LOOP).
        const size_t segments = mode == TINYGLTF_MODE_LINE ? n / 2 : (mode == TINYGLTF_MODE_LINE_STRIP ? n - 1 : n);
        out.reserve(3 * segments);
        for (size_t s = 0; s < segments; ++s) {
            const uint32_t a = mode == TINYGLTF_MODE_LINE ? idx[2 * s] : idx[s];
            const uint32_t b = mode == TINYGLTF_MODE_LINE ? idx[2 * s + 1] : idx[(s + 1) % n];
            out.insert(out.end(), {a, b, b});
        }
    }
    return out;
}

/// Reads a primitive's index accessor (u8/u16/u32 SCALAR) or makes 0..vertex_count-1.
std::vector<uint32_t> read_indices(const Source& src, const tinygltf::Primitive& prim,
                                   size_t vertex_count, const std::string& where) {
    std::vector<uint32_t> idx;
    if (prim.indices < 0) {
        idx.resize(vertex_count);
        for (size_t i = 0; i < vertex_count; ++i) idx[i] = uint32_t(i);
        return idx;
    }
    AccessorView view = view_accessor(src, prim.indices, where + " indices");
    int ct = view.component_type;
    bool integer = ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                   ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ||
                   ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    if (!integer || view.components != 1)
        src.fail(where + ": indices must be SCALAR unsigned byte/short/int (componentType " +
                 std::to_string(ct) + ")");
    idx.resize(view.count);
    for (size_t i = 0; i < view.count; ++i) {
        idx[i] = view.index(i);
        if (idx[i] >= vertex_count)
            src.fail(where + ": index " + std::to_string(idx[i]) + " out of range (vertex count " +
                     std::to_string(vertex_count) + ")");
    }
    return idx;
}

/// TEXCOORD_0 of the primitive's corners (float, or normalised unsigned byte/short), appended to
/// out.uvs; a mesh gets uvs once any primitive has them (earlier corners filled with (0, 0)).
void read_texcoords(const Source& src, const tinygltf::Primitive& prim, size_t vertex_count,
                    const std::vector<uint32_t>& list, const std::string& where, Mesh& out) {
    auto it = prim.attributes.find("TEXCOORD_0");
    const size_t before = out.positions.size() - list.size();
    if (it == prim.attributes.end()) {
        if (!out.uvs.empty()) out.uvs.resize(out.positions.size(), glm::vec2(0.0f));
        return;
    }
    AccessorView uv = view_accessor(src, it->second, where + " TEXCOORD_0");
    if (uv.components != 2 || uv.count < vertex_count)
        src.fail(where + ": TEXCOORD_0 must be VEC2 with one entry per vertex");
    out.uvs.resize(before, glm::vec2(0.0f));
    for (uint32_t i : list) out.uvs.emplace_back(uv.component(i, 0), uv.component(i, 1));
}

/// A POINTS or LINES primitive's radii (docs/accel.md, "Spheres and capsules"): its _RADIUS
/// attribute, one positive finite float per vertex, appended to out.radii for the spheres or
/// capsules `list` names (three corners each); a capsule of two radii fills out.end_radii.
void read_radii(const Source& src, const tinygltf::Primitive& prim, size_t vertex_count,
                const std::vector<uint32_t>& list, const std::string& where, Mesh& out) {
    auto it = prim.attributes.find("_RADIUS");
    if (it == prim.attributes.end())
        src.fail(where + ": POINTS and LINES primitives are traced as spheres and capsules and need a _RADIUS "
                         "attribute (float SCALAR, one radius per vertex; docs/accel.md)");
    AccessorView radius = view_accessor(src, it->second, where + " _RADIUS");
    if (radius.component_type != TINYGLTF_COMPONENT_TYPE_FLOAT || radius.components != 1 || radius.count < vertex_count)
        src.fail(where + ": _RADIUS must be float SCALAR with one entry per vertex");
    const size_t before = out.triangle_count() - list.size() / 3;  // the mesh's earlier triangles
    out.radii.resize(before, 0.0f);
    if (!out.end_radii.empty()) out.end_radii.resize(before, 0.0f);
    for (size_t k = 0; k < list.size(); k += 3) {
        float r[2];
        for (int end = 0; end < 2; ++end) {
            const uint32_t vertex = list[k + size_t(end)];
            r[end] = radius.component(vertex, 0);
            if (!(r[end] > 0.0f) || !std::isfinite(r[end]))
                src.fail(where + ": vertex " + std::to_string(vertex) + " has _RADIUS " + std::to_string(r[end]) +
                         " (a radius must be positive and finite)");
        }
        const bool two_radii = !out.end_radii.empty() || r[0] != r[1];
        if (two_radii && out.end_radii.empty()) out.end_radii = out.radii;  // the earlier ones' ends: their radius
        out.radii.push_back(r[0]);
        if (two_radii) out.end_radii.push_back(r[1]);
    }
}

/// Appends one primitive's triangles or spheres (positions and material ids) to `out`.
void read_primitive(const Source& src, const tinygltf::Primitive& prim, const std::string& where,
                    Scene& scene, Mesh& out) {
    int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        mode != TINYGLTF_MODE_TRIANGLE_FAN && mode != TINYGLTF_MODE_POINTS && !is_line_mode(mode))
        src.fail(where + ": unsupported primitive mode " + std::to_string(mode) + " (" + mode_name(mode) + ")");
    auto pos_it = prim.attributes.find("POSITION");
    if (pos_it == prim.attributes.end()) src.fail(where + ": no POSITION attribute");
    AccessorView pos = view_accessor(src, pos_it->second, where + " POSITION");
    if (pos.component_type != TINYGLTF_COMPONENT_TYPE_FLOAT || pos.components != 3)
        src.fail(where + ": POSITION must be float VEC3 (componentType " +
                 std::to_string(pos.component_type) + ", " + std::to_string(pos.components) +
                 " components; KHR_mesh_quantization is not supported)");

    const tinygltf::Model& m = *src.model;
    uint32_t material;
    if (prim.material < 0) {
        material = scene.default_material();
    } else if (size_t(prim.material) < m.materials.size()) {
        material = uint32_t(prim.material);
    } else {
        src.fail(where + ": material index " + std::to_string(prim.material) + " out of range (" +
                 std::to_string(m.materials.size()) + " materials)");
    }

    std::vector<uint32_t> list = triangle_list(read_indices(src, prim, pos.count, where), mode);
    if (mode == TINYGLTF_MODE_TRIANGLES && prim.indices >= 0 &&
        m.accessors[size_t(prim.indices)].count % 3 != 0)
        scene.warnings.push_back(where + ": index count not a multiple of 3; extra indices ignored");
    out.positions.reserve(out.positions.size() + list.size());
    for (uint32_t i : list) {
        const unsigned char* p = pos.data + size_t(i) * pos.stride;
        float xyz[3];
        std::memcpy(xyz, p, sizeof(xyz));
        out.positions.emplace_back(xyz[0], xyz[1], xyz[2]);
    }
    out.materials.insert(out.materials.end(), list.size() / 3, material);
    if (mode == TINYGLTF_MODE_POINTS || is_line_mode(mode)) {
        read_radii(src, prim, pos.count, list, where, out);
        if (!out.uvs.empty()) out.uvs.resize(out.positions.size(), glm::vec2(0.0f));  // spheres map their own
    } else {
        read_texcoords(src, prim, pos.count, list, where, out);
    }
    if (!out.radii.empty()) out.radii.resize(out.triangle_count(), 0.0f);  // triangles after spheres
    if (!out.end_radii.empty()) out.end_radii.resize(out.triangle_count(), 0.0f);
}

}  // namespace

std::vector<uint32_t> primitive_corners(const Source& src, const tinygltf::Primitive& prim,
                                        size_t vertex_count, const std::string& where) {
    return triangle_list(read_indices(src, prim, vertex_count, where),
                         prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode);
}

uint32_t read_mesh(const Source& src, int mesh_index, Scene& scene) {
    const tinygltf::Mesh& gm = src.model->meshes[size_t(mesh_index)];
    std::string mesh_name = element("mesh", size_t(mesh_index), gm.name);
    Mesh mesh;
    mesh.name = gm.name.empty() ? "mesh_" + std::to_string(mesh_index) : gm.name;
    for (size_t p = 0; p < gm.primitives.size(); ++p) {
        const tinygltf::Primitive& prim = gm.primitives[p];
        std::string where = mesh_name + " primitive " + std::to_string(p);
        read_primitive(src, prim, where, scene, mesh);
    }
    scene.meshes.push_back(std::move(mesh));
    return uint32_t(scene.meshes.size() - 1);
}

}  // namespace rtsim::gltf
