// GltfWriter: procedural geometry to a glTF 2.0 file through tinygltf's serializer.
#include "traces/scene/gltf_writer.h"

#include <algorithm>
#include <cstring>
#include <filesystem>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <tiny_gltf.h>

#include "traces/common/error.h"

namespace rtsim {

void TriangleSoup::add_quad(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d,
                            const Vec3& outward) {
    uint32_t ia = add_vertex(a), ib = add_vertex(b), ic = add_vertex(c), id = add_vertex(d);
    if (glm::dot(glm::cross(b - a, c - a), outward) >= 0.0f) {
        add_triangle(ia, ib, ic);
        add_triangle(ia, ic, id);
    } else {
        add_triangle(ia, ic, ib);
        add_triangle(ia, id, ic);
    }
}

void TriangleSoup::add_box(const glm::dmat4& m) {
    auto p = [&](double x, double y, double z) { return Vec3(m * glm::dvec4(x, y, z, 1.0)); };
    Vec3 center = p(0, 0, 0);
    // Each face: fixed axis a, sign s; corners in order around the face.
    for (int a = 0; a < 3; ++a) {
        for (double s : {-0.5, 0.5}) {
            Vec3 q[4];
            const double uv[4][2] = {{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}};
            for (int k = 0; k < 4; ++k) {
                double c[3];
                c[a] = s;
                c[(a + 1) % 3] = uv[k][0];
                c[(a + 2) % 3] = uv[k][1];
                q[k] = p(c[0], c[1], c[2]);
            }
            Vec3 face_center = (q[0] + q[2]) * 0.5f;
            add_quad(q[0], q[1], q[2], q[3], face_center - center);
        }
    }
}

struct GltfWriter::Impl {
    tinygltf::Model model;
    std::vector<unsigned char> bin;

    /// Appends raw bytes (4-byte aligned) as a bufferView; returns its index.
    int add_view(const void* data, size_t bytes, int target) {
        while (bin.size() % 4) bin.push_back(0);
        tinygltf::BufferView bv;
        bv.buffer = 0;
        bv.byteOffset = bin.size();
        bv.byteLength = bytes;
        if (target >= 0) bv.target = target;  // animation and skin data name no target
        bin.resize(bin.size() + bytes);
        if (bytes) std::memcpy(bin.data() + bv.byteOffset, data, bytes);
        model.bufferViews.push_back(bv);
        return int(model.bufferViews.size() - 1);
    }
    int add_accessor(int view, int component_type, int type, size_t count) {
        tinygltf::Accessor acc;
        acc.bufferView = view;
        acc.byteOffset = 0;
        acc.componentType = component_type;
        acc.type = type;
        acc.count = count;
        model.accessors.push_back(acc);
        return int(model.accessors.size() - 1);
    }
    /// A triangle primitive of `soup` (POSITION with the min/max glTF 2.0 section 3.6.2.4 asks for).
    tinygltf::Primitive add_primitive(const TriangleSoup& soup, int material) {
        Aabb box;
        for (const Vec3& v : soup.vertices) box.grow(v);
        const int pa = add_accessor(add_view(soup.vertices.data(), soup.vertices.size() * sizeof(Vec3), TINYGLTF_TARGET_ARRAY_BUFFER),
                                    TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, soup.vertices.size());
        model.accessors[size_t(pa)].minValues = {box.lo.x, box.lo.y, box.lo.z};
        model.accessors[size_t(pa)].maxValues = {box.hi.x, box.hi.y, box.hi.z};
        tinygltf::Primitive prim;
        prim.attributes["POSITION"] = pa;
        prim.indices =
            add_accessor(add_view(soup.indices.data(), soup.indices.size() * sizeof(uint32_t), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
                         TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, soup.indices.size());
        prim.material = material;
        prim.mode = TINYGLTF_MODE_TRIANGLES;
        return prim;
    }
    void add_root(tinygltf::Node node) {
        model.nodes.push_back(std::move(node));
        model.scenes[0].nodes.push_back(int(model.nodes.size() - 1));
    }
    void use_extension(const std::string& name) {
        auto& used = model.extensionsUsed;
        if (std::find(used.begin(), used.end(), name) == used.end()) used.push_back(name);
    }
};

GltfWriter::GltfWriter() : m_impl(new Impl) {
    m_impl->model.asset.version = "2.0";
    m_impl->model.asset.generator = "rtsim procedural scenes";
    m_impl->model.scenes.resize(1);
    m_impl->model.defaultScene = 0;
}

GltfWriter::~GltfWriter() { delete m_impl; }

int GltfWriter::add_material(const Material& m) {
    tinygltf::Material gm;
    gm.name = m.name;
    gm.pbrMetallicRoughness.baseColorFactor = {m.base_color.x, m.base_color.y, m.base_color.z,
                                               m.base_color.w};
    gm.pbrMetallicRoughness.metallicFactor = m.metallic;
    gm.pbrMetallicRoughness.roughnessFactor = m.roughness;
    // emissiveFactor is limited to [0, 1]; larger radiance goes into the strength extension.
    float strength = std::max({m.emissive.x, m.emissive.y, m.emissive.z, 1.0f});
    gm.emissiveFactor = {m.emissive.x / strength, m.emissive.y / strength, m.emissive.z / strength};
    if (strength > 1.0f) {
        tinygltf::Value::Object ext{{"emissiveStrength", tinygltf::Value(double(strength))}};
        gm.extensions["KHR_materials_emissive_strength"] = tinygltf::Value(ext);
        m_impl->use_extension("KHR_materials_emissive_strength");
    }
    if (m.alpha_mode == AlphaMode::mask) {
        // The alpha test without a texture: the loader's stochastic test passes this fraction
        // of a MASK triangle's hits (extras.textureAlphaCoverage, as the stripped shared scenes).
        gm.alphaMode = "MASK";
        gm.alphaCutoff = m.alpha_cutoff;
        gm.extras = tinygltf::Value(tinygltf::Value::Object{{"textureAlphaCoverage", tinygltf::Value(double(m.alpha_coverage))}});
    }
    m_impl->model.materials.push_back(gm);
    return int(m_impl->model.materials.size() - 1);
}

void GltfWriter::set_mesh_motion(int mesh, const ProceduralMotion& motion) {
    m_impl->model.meshes.at(size_t(mesh)).extras = procedural_motion_to_value(motion);
}

int GltfWriter::add_mesh(const std::string& name,
                         const std::vector<std::pair<const TriangleSoup*, int>>& parts) {
    tinygltf::Mesh mesh;
    mesh.name = name;
    for (const auto& [soup, material] : parts) mesh.primitives.push_back(m_impl->add_primitive(*soup, material));
    m_impl->model.meshes.push_back(mesh);
    return int(m_impl->model.meshes.size() - 1);
}

void GltfWriter::add_skinned_mesh_node(const std::string& name, const TriangleSoup& soup, int material,
                                       const SkinWeights& weights, const Skeleton& skeleton) {
    Impl& g = *m_impl;
    const size_t nv = soup.vertices.size(), nj = skeleton.joints.size(), nk = skeleton.key_times.size();
    if (weights.joints.size() != nv || weights.weights.size() != nv || nj == 0 || nk == 0)
        throw Error("skinned mesh '" + name + "': joints and weights need one entry per vertex, and joints and key times");
    tinygltf::Primitive prim = g.add_primitive(soup, material);
    prim.attributes["JOINTS_0"] =
        g.add_accessor(g.add_view(weights.joints.data(), nv * sizeof(glm::u16vec4), TINYGLTF_TARGET_ARRAY_BUFFER),
                       TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_VEC4, nv);
    prim.attributes["WEIGHTS_0"] =
        g.add_accessor(g.add_view(weights.weights.data(), nv * sizeof(glm::vec4), TINYGLTF_TARGET_ARRAY_BUFFER),
                       TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC4, nv);
    tinygltf::Mesh mesh;
    mesh.name = name;
    mesh.primitives.push_back(prim);
    g.model.meshes.push_back(mesh);

    // The joints as nodes (the root joint a root of the scene), and their bind-pose world matrices.
    tinygltf::Skin skin;
    skin.name = name + "_skin";
    std::vector<glm::mat4> inverse_bind(nj);
    std::vector<glm::dmat4> bind(nj);
    for (size_t j = 0; j < nj; ++j) {
        const SkinJoint& joint = skeleton.joints[j];
        if (joint.parent >= int(j) || joint.rotations.size() != nk)
            throw Error("skinned mesh '" + name + "': joint " + std::to_string(j) + " needs an earlier parent and a rotation per key");
        tinygltf::Node node;
        node.name = joint.name;
        node.translation = {joint.translation.x, joint.translation.y, joint.translation.z};
        const glm::dmat4 local = glm::translate(glm::dmat4(1.0), glm::dvec3(joint.translation));
        bind[j] = joint.parent < 0 ? local : bind[size_t(joint.parent)] * local;
        inverse_bind[j] = glm::mat4(glm::inverse(bind[j]));
        g.model.nodes.push_back(node);
        const int index = int(g.model.nodes.size() - 1);
        skin.joints.push_back(index);
        if (joint.parent < 0) g.model.scenes[0].nodes.push_back(index);
        else g.model.nodes[size_t(skin.joints[size_t(joint.parent)])].children.push_back(index);
    }
    skin.inverseBindMatrices = g.add_accessor(g.add_view(inverse_bind.data(), nj * sizeof(glm::mat4), -1),
                                              TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_MAT4, nj);
    g.model.skins.push_back(skin);

    tinygltf::Node node;
    node.name = name;
    node.mesh = int(g.model.meshes.size() - 1);
    node.skin = int(g.model.skins.size() - 1);
    g.add_root(node);

    // One LINEAR rotation channel per joint, all on the same key times (input needs min/max).
    tinygltf::Animation anim;
    anim.name = name + "_motion";
    const int input = g.add_accessor(g.add_view(skeleton.key_times.data(), nk * sizeof(float), -1),
                                     TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_SCALAR, nk);
    g.model.accessors[size_t(input)].minValues = {skeleton.key_times.front()};
    g.model.accessors[size_t(input)].maxValues = {skeleton.key_times.back()};
    for (size_t j = 0; j < nj; ++j) {
        std::vector<float> xyzw;
        for (const glm::quat& q : skeleton.joints[j].rotations) xyzw.insert(xyzw.end(), {q.x, q.y, q.z, q.w});
        tinygltf::AnimationSampler sampler;
        sampler.input = input;
        sampler.output = g.add_accessor(g.add_view(xyzw.data(), xyzw.size() * sizeof(float), -1),
                                        TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC4, nk);
        sampler.interpolation = "LINEAR";
        anim.samplers.push_back(sampler);
        tinygltf::AnimationChannel channel;
        channel.sampler = int(anim.samplers.size() - 1);
        channel.target_node = skin.joints[j];
        channel.target_path = "rotation";
        anim.channels.push_back(channel);
    }
    g.model.animations.push_back(anim);
}

int GltfWriter::add_sphere_mesh(const std::string& name, const std::vector<Vec3>& centres,
                                const std::vector<float>& radii, int material) {
    if (centres.size() != radii.size() || centres.empty())
        throw Error("sphere mesh '" + name + "': one radius per centre, and at least one sphere");
    Impl& g = *m_impl;
    Aabb box;
    for (const Vec3& c : centres) box.grow(c);
    const int pa = g.add_accessor(g.add_view(centres.data(), centres.size() * sizeof(Vec3), TINYGLTF_TARGET_ARRAY_BUFFER),
                                  TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, centres.size());
    g.model.accessors[size_t(pa)].minValues = {box.lo.x, box.lo.y, box.lo.z};
    g.model.accessors[size_t(pa)].maxValues = {box.hi.x, box.hi.y, box.hi.z};
    tinygltf::Primitive prim;
    prim.attributes["POSITION"] = pa;
    prim.attributes["_RADIUS"] = g.add_accessor(g.add_view(radii.data(), radii.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER),
                                                TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_SCALAR, radii.size());
    prim.material = material;
    prim.mode = TINYGLTF_MODE_POINTS;
    tinygltf::Mesh mesh;
    mesh.name = name;
    mesh.primitives.push_back(prim);
    g.model.meshes.push_back(mesh);
    return int(g.model.meshes.size() - 1);
}

int GltfWriter::add_capsule_mesh(const std::string& name, const std::vector<Vec3>& vertices,
                                 const std::vector<float>& radii, const std::vector<uint32_t>& segments, int material) {
    if (vertices.size() != radii.size() || segments.empty() || segments.size() % 2)
        throw Error("capsule mesh '" + name + "': one radius per vertex, and index pairs");
    int mesh = add_sphere_mesh(name, vertices, radii, material);  // POSITION and _RADIUS alike
    Impl& g = *m_impl;
    tinygltf::Primitive& prim = g.model.meshes[size_t(mesh)].primitives[0];
    prim.indices = g.add_accessor(g.add_view(segments.data(), segments.size() * sizeof(uint32_t),
                                             TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
                                  TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, segments.size());
    prim.mode = TINYGLTF_MODE_LINE;
    return mesh;
}

void GltfWriter::add_mesh_node(const std::string& name, int mesh, const glm::dmat4& transform) {
    tinygltf::Node node;
    node.name = name;
    node.mesh = mesh;
    if (transform != glm::dmat4(1.0))
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) node.matrix.push_back(transform[c][r]);
    m_impl->add_root(node);
}

namespace {

/// Node rotation (x, y, z, w) turning the node's -Z towards `forward`, +Y towards `up`.
std::vector<double> look_rotation(const glm::dvec3& forward, const glm::dvec3& up_hint) {
    glm::dvec3 f = glm::normalize(forward);
    glm::dvec3 hint = std::abs(glm::dot(f, glm::normalize(up_hint))) > 0.999 ? glm::dvec3(1, 0, 0) : up_hint;
    glm::dvec3 r = glm::normalize(glm::cross(f, hint));
    glm::dvec3 u = glm::cross(r, f);
    glm::dquat q = glm::quat_cast(glm::dmat3(r, u, -f));
    return {q.x, q.y, q.z, q.w};
}

}  // namespace

void GltfWriter::add_camera(const std::string& name, const Vec3& eye, const Vec3& target, float yfov,
                            float aspect) {
    tinygltf::Camera cam;
    cam.name = name;
    cam.type = "perspective";
    cam.perspective.yfov = yfov;
    cam.perspective.aspectRatio = aspect;
    cam.perspective.znear = 0.01;
    cam.perspective.zfar = 1.0e7;
    m_impl->model.cameras.push_back(cam);
    tinygltf::Node node;
    node.name = name;
    node.camera = int(m_impl->model.cameras.size() - 1);
    node.translation = {eye.x, eye.y, eye.z};
    node.rotation = look_rotation(glm::dvec3(target - eye), glm::dvec3(0, 1, 0));
    m_impl->add_root(node);
}

void GltfWriter::add_light(const std::string& name, LightType type, const Vec3& position,
                           const Vec3& target, const Vec3& color, float intensity) {
    tinygltf::Light light;
    light.name = name;
    light.type = type == LightType::point ? "point" : type == LightType::spot ? "spot" : "directional";
    light.color = {color.x, color.y, color.z};
    light.intensity = intensity;
    m_impl->model.lights.push_back(light);
    tinygltf::Node node;
    node.name = name;
    node.translation = {position.x, position.y, position.z};
    if (type != LightType::point) node.rotation = look_rotation(glm::dvec3(target - position), {0, 1, 0});
    tinygltf::Value::Object ext{{"light", tinygltf::Value(int(m_impl->model.lights.size() - 1))}};
    node.extensions["KHR_lights_punctual"] = tinygltf::Value(ext);
    m_impl->use_extension("KHR_lights_punctual");
    m_impl->add_root(node);
}

std::string GltfWriter::write(const std::string& dir, const std::string& name) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    std::string path = (std::filesystem::path(dir) / (name + ".gltf")).string();
    tinygltf::Buffer buffer;
    buffer.uri = name + ".bin";
    buffer.data = std::move(m_impl->bin);
    m_impl->model.buffers = {std::move(buffer)};
    tinygltf::TinyGLTF writer;
    bool ok = writer.WriteGltfSceneToFile(&m_impl->model, path, false /*embedImages*/,
                                          false /*embedBuffers*/, true /*pretty*/, false /*binary*/);
    m_impl->bin = std::move(m_impl->model.buffers[0].data);
    if (!ok) throw Error(path + ": cannot write the procedural scene (directory writable?)");
    return path;
}

}  // namespace rtsim
