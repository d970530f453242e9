// glTF skins and morph targets as Scene::animation (glTF 2.0 sections 3.7.2.2, 3.7.3, 3.11).
//
// A deforming mesh's pose at time t: the file's animation channels set the nodes' TRS and the
// morph weights, then per triangle corner
//   p = base + sum_k w_k * delta_k                                        (morph targets)
//   p' = sum_i weight_i * jointMatrix_i * p                                (skin)
//   jointMatrix_i = inverse(restGlobal(meshNode)) * global_t(joint_i) * inverseBindMatrix_i
// Skin vs node transform: the spec ignores the skinned mesh node's own transform (the joints
// place the mesh). The loader keeps placing the mesh's instance by the mesh node's rest global
// transform, so the pose is written in that node's space, with the *rest* global inverted: the
// world position is then global_t(joint) * inverseBindMatrix * p exactly as the spec says, even
// when the mesh node itself is animated. A glTF mesh placed by several nodes deforms as the first
// placing node (scene order) says (its skin and morph weights); all its instances share that pose.
#include "traces/scene/gltf_animation.h"

#include <cmath>
#include <map>

#include <glm/gtc/matrix_transform.hpp>

namespace rtsim::gltf {

namespace {

struct Trs {
    glm::dvec3 t{0.0};
    glm::dquat r{1.0, 0.0, 0.0, 0.0};
    glm::dvec3 s{1.0};
    bool has_matrix = false;  ///< the node gives a matrix (never animated, spec 3.11)
    glm::dmat4 matrix{1.0};

    glm::dmat4 to_matrix() const {
        if (has_matrix) return matrix;
        return glm::translate(glm::dmat4(1.0), t) * glm::mat4_cast(r) * glm::scale(glm::dmat4(1.0), s);
    }
};

Trs rest_trs(const tinygltf::Node& n) {
    Trs x;
    if (n.matrix.size() == 16) {
        x.has_matrix = true;
        for (int i = 0; i < 16; ++i) x.matrix[i / 4][i % 4] = n.matrix[size_t(i)];
        return x;
    }
    if (n.translation.size() == 3) x.t = {n.translation[0], n.translation[1], n.translation[2]};
    if (n.rotation.size() == 4) x.r = glm::dquat(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]);
    if (n.scale.size() == 3) x.s = {n.scale[0], n.scale[1], n.scale[2]};
    return x;
}

struct Skin {
    std::vector<int> joints;               ///< node indices
    std::vector<glm::dmat4> inverse_bind;  ///< one per joint
};

/// One deforming Scene mesh: its rest corners and what moves them, per corner.
struct Deformer {
    int node = -1;  ///< the glTF node whose skin and weights drive it
    int skin = -1;
    std::vector<Vec3> base;                 ///< Mesh::positions
    std::vector<std::vector<Vec3>> deltas;  ///< per morph target, per corner
    std::vector<float> weights;             ///< default morph weights (node, else mesh, else 0)
    std::vector<glm::uvec4> joints;         ///< per corner, indices into the skin's joints
    std::vector<glm::vec4> joint_weights;   ///< per corner, normalised to sum 1
};

Skin read_skin(const Source& src, size_t index) {
    const tinygltf::Skin& s = src.model->skins[index];
    const std::string where = element("skin", index, s.name);
    Skin out;
    for (int j : s.joints) {
        if (j < 0 || size_t(j) >= src.model->nodes.size())
            src.fail(where + ": joint node " + std::to_string(j) + " out of range (" +
                     std::to_string(src.model->nodes.size()) + " nodes)");
        out.joints.push_back(j);
    }
    if (out.joints.empty()) src.fail(where + ": no joints");
    out.inverse_bind.assign(out.joints.size(), glm::dmat4(1.0));
    if (s.inverseBindMatrices >= 0) {
        AccessorView m = view_accessor(src, s.inverseBindMatrices, where + " inverseBindMatrices");
        if (m.components != 16 || m.count < out.joints.size())
            src.fail(where + ": inverseBindMatrices must be MAT4 with one matrix per joint (" +
                     std::to_string(m.count) + " for " + std::to_string(out.joints.size()) + " joints)");
        for (size_t j = 0; j < out.joints.size(); ++j)
            for (int c = 0; c < 16; ++c) {
                float v = m.component(j, c);
                if (!std::isfinite(v)) src.fail(where + ": inverseBindMatrices " + std::to_string(j) + " is not finite");
                out.inverse_bind[j][c / 4][c % 4] = v;
            }
    }
    return out;
}

/// JOINTS_0 / WEIGHTS_0 of one primitive's corners, appended to d.
void read_skin_corners(const Source& src, const tinygltf::Primitive& prim, const std::vector<uint32_t>& corners,
                       size_t vertex_count, size_t joint_count, const std::string& where, Deformer& d) {
    auto j_it = prim.attributes.find("JOINTS_0"), w_it = prim.attributes.find("WEIGHTS_0");
    if (j_it == prim.attributes.end() || w_it == prim.attributes.end())
        src.fail(where + ": skinned but lacks JOINTS_0 or WEIGHTS_0");
    AccessorView j = view_accessor(src, j_it->second, where + " JOINTS_0");
    AccessorView w = view_accessor(src, w_it->second, where + " WEIGHTS_0");
    if (j.components != 4 || w.components != 4 || j.count != vertex_count || w.count != vertex_count)
        src.fail(where + ": JOINTS_0 and WEIGHTS_0 must be VEC4 with one entry per vertex (" +
                 std::to_string(j.count) + " and " + std::to_string(w.count) + " entries, " +
                 std::to_string(vertex_count) + " vertices)");
    for (uint32_t v : corners) {
        glm::uvec4 ji;
        glm::vec4 wi;
        for (int c = 0; c < 4; ++c) {
            ji[c] = uint32_t(j.component(v, c));
            wi[c] = w.component(v, c);
            if (!std::isfinite(wi[c]) || wi[c] < 0.0f)
                src.fail(where + ": WEIGHTS_0 of vertex " + std::to_string(v) + " is negative or not finite");
            if (wi[c] > 0.0f && ji[c] >= joint_count)
                src.fail(where + ": JOINTS_0 of vertex " + std::to_string(v) + " names joint " +
                         std::to_string(ji[c]) + ", the skin has " + std::to_string(joint_count) + " joints");
        }
        float sum = wi[0] + wi[1] + wi[2] + wi[3];
        if (!(sum > 0.0f)) src.fail(where + ": WEIGHTS_0 of vertex " + std::to_string(v) + " are all zero");
        d.joints.push_back(ji);
        d.joint_weights.push_back(wi / sum);  // the spec asks for sum 1; quantised weights drift
    }
}

/// Morph target POSITION deltas of one primitive's corners, appended to d.deltas[k].
void read_morph_corners(const Source& src, const tinygltf::Primitive& prim, const std::vector<uint32_t>& corners,
                        size_t vertex_count, const std::string& where, Deformer& d) {
    if (prim.targets.size() != d.deltas.size())
        src.fail(where + ": " + std::to_string(prim.targets.size()) + " morph targets, the mesh's first primitive has " +
                 std::to_string(d.deltas.size()));
    for (size_t k = 0; k < prim.targets.size(); ++k) {
        auto it = prim.targets[k].find("POSITION");
        if (it == prim.targets[k].end()) {
            d.deltas[k].insert(d.deltas[k].end(), corners.size(), Vec3(0.0f));
            continue;
        }
        const std::string twhere = where + " target " + std::to_string(k) + " POSITION";
        AccessorView p = view_accessor(src, it->second, twhere);
        if (p.components != 3 || p.count != vertex_count)
            src.fail(twhere + ": must be VEC3 with one entry per vertex");
        for (uint32_t v : corners) {
            Vec3 delta(p.component(v, 0), p.component(v, 1), p.component(v, 2));
            if (!std::isfinite(delta.x) || !std::isfinite(delta.y) || !std::isfinite(delta.z))
                src.fail(twhere + ": vertex " + std::to_string(v) + " is not finite");
            d.deltas[k].push_back(delta);
        }
    }
}

Deformer read_deformer(const Source& src, size_t gmesh, int node, const std::vector<Skin>& skins,
                       const Mesh& mesh) {
    const tinygltf::Model& m = *src.model;
    const tinygltf::Mesh& gm = m.meshes[gmesh];
    const tinygltf::Node& n = m.nodes[size_t(node)];
    Deformer d;
    d.node = node;
    d.skin = n.skin;
    d.base = mesh.positions;
    const size_t targets = gm.primitives.empty() ? 0 : gm.primitives[0].targets.size();
    d.deltas.resize(targets);
    d.weights.assign(targets, 0.0f);
    const std::vector<double>& w = !n.weights.empty() ? n.weights : gm.weights;
    if (!w.empty() && w.size() != targets)
        src.fail(element("mesh", gmesh, gm.name) + ": " + std::to_string(w.size()) + " default weights for " +
                 std::to_string(targets) + " morph targets");
    for (size_t k = 0; k < w.size(); ++k) d.weights[k] = float(w[k]);
    for (size_t p = 0; p < gm.primitives.size(); ++p) {
        const tinygltf::Primitive& prim = gm.primitives[p];
        const std::string where = element("mesh", gmesh, gm.name) + " primitive " + std::to_string(p);
        auto pos = prim.attributes.find("POSITION");
        const size_t vertex_count = m.accessors[size_t(pos->second)].count;
        std::vector<uint32_t> corners = primitive_corners(src, prim, vertex_count, where);
        read_morph_corners(src, prim, corners, vertex_count, where, d);
        if (d.skin >= 0)
            read_skin_corners(src, prim, corners, vertex_count, skins[size_t(d.skin)].joints.size(),
                              element("skin", size_t(d.skin), m.skins[size_t(d.skin)].name) + ": " + where, d);
    }
    if ((d.skin >= 0 && d.joints.size() != d.base.size()) ||
        (targets > 0 && d.deltas[0].size() != d.base.size()))
        src.fail(element("mesh", gmesh, gm.name) + ": skin or morph corners do not match its triangles");
    return d;
}

class GltfAnimation : public MeshAnimation {
public:
    GltfAnimation(const Source& src, std::vector<Channel> channels, std::vector<Skin> skins,
                  std::map<uint32_t, Deformer> meshes)
        : m_file(src.file), m_channels(std::move(channels)), m_skins(std::move(skins)),
          m_meshes(std::move(meshes)) {
        const tinygltf::Model& m = *src.model;
        m_parent.assign(m.nodes.size(), -1);
        for (size_t n = 0; n < m.nodes.size(); ++n) {
            m_rest.push_back(rest_trs(m.nodes[n]));
            for (int c : m.nodes[n].children)
                if (c >= 0 && size_t(c) < m.nodes.size()) m_parent[size_t(c)] = int(n);
        }
        // Parents before children (the loader has refused cycles in the default scene; a node
        // outside it on a cycle keeps its local transform as global).
        std::vector<int> stack;
        for (size_t n = 0; n < m.nodes.size(); ++n)
            if (m_parent[n] < 0) stack.push_back(int(n));
        while (!stack.empty()) {
            int n = stack.back();
            stack.pop_back();
            m_order.push_back(n);
            for (int c : m.nodes[size_t(n)].children)
                if (c >= 0 && size_t(c) < m.nodes.size() && m_parent[size_t(c)] == n) stack.push_back(c);
        }
        for (const Channel& ch : m_channels) {
            m_duration = std::max(m_duration, double(ch.sampler.times.back()));
            if (ch.path != Channel::Path::weights && m_rest[size_t(ch.node)].has_matrix)
                src.fail(element("node", size_t(ch.node), m.nodes[size_t(ch.node)].name) +
                         ": animated but given as a matrix (glTF 2.0 section 3.11 forbids it)");
        }
        m_rest_global = globals(m_rest);
    }

    bool deforms(uint32_t mesh) const override { return m_meshes.count(mesh) != 0; }

    void pose(uint32_t mesh, uint32_t frame, std::vector<Vec3>* out) const override {
        auto it = m_meshes.find(mesh);
        if (it == m_meshes.end()) throw Error(m_file + ": mesh " + std::to_string(mesh) + " does not deform");
        const Deformer& d = it->second;
        // One clip looping over the longest channel.
        double t = double(frame) / frames_per_second();
        if (m_duration > 0.0) t = std::fmod(t, m_duration);
        std::vector<Trs> local = m_rest;
        std::vector<float> weights = d.weights;
        float value[4];
        for (const Channel& ch : m_channels) {
            Trs& x = local[size_t(ch.node)];
            switch (ch.path) {
                case Channel::Path::translation:
                    ch.sampler.sample(t, false, value);
                    x.t = {value[0], value[1], value[2]};
                    break;
                case Channel::Path::rotation:
                    ch.sampler.sample(t, true, value);
                    x.r = glm::dquat(value[3], value[0], value[1], value[2]);
                    break;
                case Channel::Path::scale:
                    ch.sampler.sample(t, false, value);
                    x.s = {value[0], value[1], value[2]};
                    break;
                case Channel::Path::weights:
                    if (ch.node == d.node && !weights.empty()) ch.sampler.sample(t, false, weights.data());
                    break;
            }
        }
        out->resize(d.base.size());
        std::vector<glm::dmat4> joint_matrix;
        if (d.skin >= 0) {
            const Skin& skin = m_skins[size_t(d.skin)];
            std::vector<glm::dmat4> global = globals(local);
            const glm::dmat4 to_mesh = glm::inverse(m_rest_global[size_t(d.node)]);
            for (size_t j = 0; j < skin.joints.size(); ++j)
                joint_matrix.push_back(to_mesh * global[size_t(skin.joints[j])] * skin.inverse_bind[j]);
        }
        for (size_t c = 0; c < d.base.size(); ++c) {
            glm::dvec3 p = d.base[c];
            for (size_t k = 0; k < d.deltas.size(); ++k) p += double(weights[k]) * glm::dvec3(d.deltas[k][c]);
            if (d.skin >= 0) {
                glm::dvec4 q(0.0);
                for (int i = 0; i < 4; ++i)
                    if (d.joint_weights[c][i] > 0.0f)
                        q += double(d.joint_weights[c][i]) * (joint_matrix[d.joints[c][i]] * glm::dvec4(p, 1.0));
                p = glm::dvec3(q);
            }
            (*out)[c] = Vec3(p);
        }
    }

    std::string description() const override {
        size_t skinned = 0;
        for (const auto& [mesh, d] : m_meshes) skinned += d.skin >= 0;
        return "glTF animation: " + std::to_string(m_meshes.size()) + " deforming meshes (" +
               std::to_string(skinned) + " skinned), " + std::to_string(m_channels.size()) +
               " channels, looping every " + std::to_string(m_duration) + " s";
    }

private:
    std::vector<glm::dmat4> globals(const std::vector<Trs>& local) const {
        std::vector<glm::dmat4> g(local.size());
        for (size_t n = 0; n < local.size(); ++n) g[n] = local[n].to_matrix();
        for (int n : m_order)
            if (m_parent[size_t(n)] >= 0) g[size_t(n)] = g[size_t(m_parent[size_t(n)])] * local[size_t(n)].to_matrix();
        return g;
    }

    std::string m_file;
    std::vector<Channel> m_channels;
    std::vector<Skin> m_skins;
    std::map<uint32_t, Deformer> m_meshes;  ///< Scene::meshes index -> what deforms it
    std::vector<Trs> m_rest;                ///< per node
    std::vector<int> m_parent;              ///< per node, -1 for roots
    std::vector<int> m_order;               ///< nodes, parents first
    std::vector<glm::dmat4> m_rest_global;  ///< per node
    double m_duration = 0.0;                ///< seconds: the longest channel
};

}  // namespace

std::shared_ptr<const MeshAnimation> read_gltf_animation(const Source& src, const std::vector<int>& mesh_of,
                                                         const Scene& scene) {
    const tinygltf::Model& m = *src.model;
    // The first node placing each Scene mesh (instances are in scene order).
    std::vector<int> node_of(scene.meshes.size(), -1);
    for (const Instance& inst : scene.instances)
        if (inst.node >= 0 && node_of[inst.mesh] < 0) node_of[inst.mesh] = inst.node;
    std::vector<Skin> skins;
    std::map<uint32_t, Deformer> meshes;
    for (size_t g = 0; g < mesh_of.size(); ++g) {
        if (mesh_of[g] < 0) continue;
        const uint32_t mesh = uint32_t(mesh_of[g]);
        const int node = node_of[mesh];
        const tinygltf::Node& n = m.nodes[size_t(node)];
        const bool morphs = !m.meshes[g].primitives.empty() && !m.meshes[g].primitives[0].targets.empty();
        if (n.skin < 0 && !morphs) continue;
        if (n.skin >= int(m.skins.size()))
            src.fail(element("node", size_t(node), n.name) + ": skin " + std::to_string(n.skin) + " out of range (" +
                     std::to_string(m.skins.size()) + " skins)");
        if (skins.empty())
            for (size_t s = 0; s < m.skins.size(); ++s) skins.push_back(read_skin(src, s));
        meshes[mesh] = read_deformer(src, g, node, skins, scene.meshes[mesh]);
    }
    if (meshes.empty()) return nullptr;
    return std::make_shared<GltfAnimation>(src, read_channels(src), std::move(skins), std::move(meshes));
}

}  // namespace rtsim::gltf
