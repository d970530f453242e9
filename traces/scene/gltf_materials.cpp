// glTF materials (core PBR + the KHR extensions that change which rays a scene calls for),
// KHR_lights_punctual lights and cameras, placed in the world by their node.
#include <glm/gtc/quaternion.hpp>

#include "traces/scene/gltf_internal.h"

namespace rtsim::gltf {

namespace {

/// Extension object `name` of a map, or a null Value.
const tinygltf::Value& extension(const tinygltf::ExtensionMap& map, const char* name) {
    static const tinygltf::Value null_value;
    auto it = map.find(name);
    return it == map.end() ? null_value : it->second;
}

glm::vec3 to_vec3(const std::vector<double>& v, glm::vec3 fallback) {
    return v.size() >= 3 ? glm::vec3(float(v[0]), float(v[1]), float(v[2])) : fallback;
}

/// glTF image index of a texture reference, -1 if it has none (the texture's source).
int texture_image(const Source& src, int texture) {
    if (texture < 0 || size_t(texture) >= src.model->textures.size()) return -1;
    const int image = src.model->textures[size_t(texture)].source;
    return image >= 0 && size_t(image) < src.model->images.size() ? image : -1;
}

/// The slots a material's textures fill: images the file has, or the slots its
/// extras.strippedTextures names ("baseColorTexture:file.jpg", "normalTexture", ...).
void read_texture_slots(const Source& src, const tinygltf::Material& gm, Material& m) {
    const int refs[kTextureSlotCount] = {gm.pbrMetallicRoughness.baseColorTexture.index, gm.normalTexture.index,
                                         gm.pbrMetallicRoughness.metallicRoughnessTexture.index,
                                         gm.emissiveTexture.index, gm.occlusionTexture.index};
    static const char* const names[kTextureSlotCount] = {"baseColorTexture", "normalTexture",
                                                         "metallicRoughnessTexture", "emissiveTexture",
                                                         "occlusionTexture"};
    for (int s = 0; s < kTextureSlotCount; ++s) {
        const int image = texture_image(src, refs[s]);
        if (image < 0) continue;
        MaterialTexture& t = m.textures[s];
        t.source = MaterialTexture::Source::image;
        t.image = image;
        const tinygltf::Image& im = src.model->images[size_t(image)];
        t.width = im.width > 0 ? uint32_t(im.width) : 0;
        t.height = im.height > 0 ? uint32_t(im.height) : 0;
    }
    // Value::Get(key) asserts on a non-object, and a material without extras has a null one.
    if (!gm.extras.IsObject()) return;
    const tinygltf::Value& stripped = gm.extras.Get("strippedTextures");
    if (stripped.IsArray())
        for (size_t i = 0; i < stripped.ArrayLen(); ++i) {
            if (!stripped.Get(int(i)).IsString()) continue;
            const std::string entry = stripped.Get(int(i)).Get<std::string>();
            const std::string slot = entry.substr(0, entry.find(':'));
            for (int s = 0; s < kTextureSlotCount; ++s)
                if (slot == names[s] && m.textures[s].source == MaterialTexture::Source::none)
                    m.textures[s].source = MaterialTexture::Source::stripped;
        }
    if (gm.extras.Has("factorsBakedFromKhronosTextureMeans"))
        m.textures_baked = gm.extras.Get("factorsBakedFromKhronosTextureMeans").IsBool() &&
                           gm.extras.Get("factorsBakedFromKhronosTextureMeans").Get<bool>();
}

Material read_material(const Source& src, size_t index) {
    const tinygltf::Material& gm = src.model->materials[index];
    std::string where = element("material", index, gm.name);
    Material m;
    m.name = gm.name.empty() ? "material_" + std::to_string(index) : gm.name;
    const auto& pbr = gm.pbrMetallicRoughness;
    if (pbr.baseColorFactor.size() == 4)
        m.base_color = glm::vec4(float(pbr.baseColorFactor[0]), float(pbr.baseColorFactor[1]),
                                 float(pbr.baseColorFactor[2]), float(pbr.baseColorFactor[3]));
    m.metallic = float(pbr.metallicFactor);
    m.roughness = float(pbr.roughnessFactor);

    // Alpha: MASK calls for the any-hit path, BLEND is traced as a transparency hint.
    if (gm.alphaMode == "OPAQUE" || gm.alphaMode.empty()) {
        m.alpha_mode = AlphaMode::opaque;
    } else if (gm.alphaMode == "MASK") {
        m.alpha_mode = AlphaMode::mask;
    } else if (gm.alphaMode == "BLEND") {
        m.alpha_mode = AlphaMode::blend;
    } else {
        src.fail(where + ": unknown alphaMode '" + gm.alphaMode + "'");
    }
    m.alpha_cutoff = float(gm.alphaCutoff);
    m.alpha_coverage = float(value_number(gm.extras, "textureAlphaCoverage", 1.0));
    if (!(m.alpha_coverage >= 0.0f && m.alpha_coverage <= 1.0f))
        src.fail(where + ": extras.textureAlphaCoverage must lie in [0, 1]");

    // Extensions that change the light transport.
    const auto& ext = gm.extensions;
    m.transmission = float(value_number(extension(ext, "KHR_materials_transmission"),
                                        "transmissionFactor", 0.0));
    m.ior = float(value_number(extension(ext, "KHR_materials_ior"), "ior", 1.5));
    float strength = float(value_number(extension(ext, "KHR_materials_emissive_strength"),
                                        "emissiveStrength", 1.0));
    m.emissive = to_vec3(gm.emissiveFactor, glm::vec3(0.0f)) * strength;
    read_texture_slots(src, gm, m);
    return m;
}

}  // namespace

void read_materials(const Source& src, Scene& scene) {
    for (size_t i = 0; i < src.model->materials.size(); ++i)
        scene.materials.push_back(read_material(src, i));
}

Light read_light(const Source& src, int light_index, const glm::dmat4& world, int node) {
    const auto& lights = src.model->lights;
    std::string where = element("node", size_t(node), src.model->nodes[size_t(node)].name);
    if (light_index < 0 || size_t(light_index) >= lights.size())
        src.fail(where + ": KHR_lights_punctual light index " + std::to_string(light_index) +
                 " out of range (" + std::to_string(lights.size()) + " lights)");
    const tinygltf::Light& gl = lights[size_t(light_index)];
    Light l;
    l.name = gl.name.empty() ? "light_" + std::to_string(light_index) : gl.name;
    if (gl.type == "point") {
        l.type = LightType::point;
    } else if (gl.type == "spot") {
        l.type = LightType::spot;
    } else if (gl.type == "directional") {
        l.type = LightType::directional;
    } else {
        src.fail(element("light", size_t(light_index), gl.name) + ": unknown type '" + gl.type + "'");
    }
    l.color = to_vec3(gl.color, glm::vec3(1.0f));
    l.intensity = float(gl.intensity);
    l.range = float(gl.range);
    l.inner_cone = float(gl.spot.innerConeAngle);
    l.outer_cone = float(gl.spot.outerConeAngle);
    // The light sits at the node's origin and points down its -Z axis.
    glm::dvec4 p = world * glm::dvec4(0.0, 0.0, 0.0, 1.0);
    glm::dvec3 d = glm::dvec3(world * glm::dvec4(0.0, 0.0, -1.0, 0.0));
    l.position = glm::vec3(p);
    if (glm::length(d) > 0.0) l.direction = glm::vec3(glm::normalize(d));
    return l;
}

Camera read_camera(const Source& src, int camera_index, const glm::dmat4& world, int node,
                   Scene& scene) {
    const auto& cameras = src.model->cameras;
    std::string where = element("node", size_t(node), src.model->nodes[size_t(node)].name);
    if (camera_index < 0 || size_t(camera_index) >= cameras.size())
        src.fail(where + ": camera index " + std::to_string(camera_index) + " out of range (" +
                 std::to_string(cameras.size()) + " cameras)");
    const tinygltf::Camera& gc = cameras[size_t(camera_index)];
    std::string cam_name = element("camera", size_t(camera_index), gc.name);
    Camera c;
    c.name = gc.name.empty() ? "camera_" + std::to_string(camera_index) : gc.name;
    if (gc.type == "perspective") {
        c.yfov = float(gc.perspective.yfov);
        c.aspect = float(gc.perspective.aspectRatio);
        if (!(c.yfov > 0.0f && c.yfov < 3.14159f)) src.fail(cam_name + ": yfov out of range");
    } else {
        scene.warnings.push_back(cam_name + ": " + gc.type +
                                 " camera read as a perspective camera (yfov 0.8)");
    }
    // Eye at the node's origin, looking down -Z with +Y up (glTF 2.0 section 3.10).
    glm::dvec3 eye = glm::dvec3(world * glm::dvec4(0.0, 0.0, 0.0, 1.0));
    glm::dvec3 fwd = glm::dvec3(world * glm::dvec4(0.0, 0.0, -1.0, 0.0));
    glm::dvec3 up = glm::dvec3(world * glm::dvec4(0.0, 1.0, 0.0, 0.0));
    if (!(glm::length(fwd) > 0.0)) src.fail(where + ": degenerate camera transform");
    fwd = glm::normalize(fwd);
    up = up - glm::dot(up, fwd) * fwd;
    if (!(glm::length(up) > 0.0)) src.fail(where + ": degenerate camera transform");
    c.eye = glm::vec3(eye);
    c.forward = glm::vec3(fwd);
    c.up = glm::vec3(glm::normalize(up));
    return c;
}

}  // namespace rtsim::gltf
