#include "traces/scene/scene.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <unordered_map>

#include "traces/common/error.h"

namespace rtsim {

uint64_t max_flat_triangles() {
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    const uint64_t memory = pages > 0 && page > 0 ? uint64_t(pages) * uint64_t(page) : (uint64_t(16) << 30);
    return std::min<uint64_t>(INT32_MAX, memory / kBytesPerFlatTriangle);
}

void check_flat_size(const std::string& source, uint64_t triangles, const std::string& what) {
    const uint64_t limit = max_flat_triangles();
    if (triangles <= limit) return;
    char text[256];
    std::snprintf(text, sizeof text,
                  " flattens to %llu triangles (about %.1f GiB to trace); the limit on this machine is "
                  "%llu triangles (physical memory at %llu B per triangle, and int32 primitive ids)",
                  static_cast<unsigned long long>(triangles),
                  double(triangles) * double(kBytesPerFlatTriangle) / double(1ull << 30),
                  static_cast<unsigned long long>(limit), static_cast<unsigned long long>(kBytesPerFlatTriangle));
    throw Error(source + ": " + what + text);
}

namespace {

bool finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

}  // namespace

void Scene::flatten() {
    uint64_t total = 0;
    for (const Instance& inst : instances) total += meshes[inst.mesh].triangle_count();
    check_flat_size(source, total, "the scene (" + std::to_string(instances.size()) +
                                       " instances, flattened into one triangle list)");
    total = 0;
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
            if (!finite(tri.v0) || !finite(tri.v1) || !finite(tri.v2))
                throw Error(source + ": mesh " + std::to_string(inst.mesh) + " '" + mesh.name + "' triangle " +
                            std::to_string(t) + (inst.node >= 0 ? " placed by node " + std::to_string(inst.node) : "") +
                            " has a non-finite vertex in world space (NaN, infinite or beyond the float range)");
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
