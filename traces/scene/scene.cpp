#include "traces/scene/scene.h"

#include <unordered_map>

namespace rtsim {

void Scene::flatten() {
    size_t total = 0;
    for (Instance& inst : instances) {
        inst.prim_base = uint32_t(total);
        total += meshes[inst.mesh].triangle_count();
    }
    triangles.clear();
    tri_material.clear();
    tri_instance.clear();
    triangles.reserve(total);
    tri_material.reserve(total);
    tri_instance.reserve(total);
    bounds = Aabb{};
    for (size_t i = 0; i < instances.size(); ++i) {
        const Instance& inst = instances[i];
        const Mesh& mesh = meshes[inst.mesh];
        // Transform in double, round once: the world-space vertex is the float nearest to the
        // exact product, whatever the depth of the node hierarchy.
        auto to_world = [&](const Vec3& p) {
            glm::dvec4 w = inst.object_to_world * glm::dvec4(p.x, p.y, p.z, 1.0);
            return Vec3(float(w.x), float(w.y), float(w.z));
        };
        for (size_t t = 0; t < mesh.triangle_count(); ++t) {
            Triangle tri{to_world(mesh.positions[3 * t]), to_world(mesh.positions[3 * t + 1]),
                         to_world(mesh.positions[3 * t + 2])};
            bounds.grow(tri.v0);
            bounds.grow(tri.v1);
            bounds.grow(tri.v2);
            triangles.push_back(tri);
            tri_material.push_back(mesh.materials[t]);
            tri_instance.push_back(uint32_t(i));
        }
    }
}

bool Scene::uses_instancing() const {
    std::unordered_map<uint32_t, int> uses;
    for (const Instance& inst : instances)
        if (++uses[inst.mesh] > 1) return true;
    return false;
}

uint32_t Scene::default_material() {
    for (size_t i = 0; i < materials.size(); ++i)
        if (materials[i].name == "rtsim_default") return uint32_t(i);
    Material m;
    m.name = "rtsim_default";
    m.base_color = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
    m.metallic = 0.0f;
    m.roughness = 1.0f;
    materials.push_back(m);
    return uint32_t(materials.size() - 1);
}

}  // namespace rtsim
