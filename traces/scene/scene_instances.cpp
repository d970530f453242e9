// Scenes kept as instances (scene.h, index_instances()): primitive ids, bounds and per-primitive
// lookups without a flattened triangle list, for two-level tracing.
#include <algorithm>
#include <limits>

#include "traces/common/error.h"
#include "traces/scene/scene.h"

namespace rtsim {

namespace {

Vec3 to_world(const glm::dmat4& m, const Vec3& p) {
    const glm::dvec4 w = m * glm::dvec4(p.x, p.y, p.z, 1.0);
    return Vec3(float(w.x), float(w.y), float(w.z));
}

}  // namespace

void Scene::index_instances() {
    uint64_t total = 0;
    std::vector<Aabb> mesh_box(meshes.size());
    for (size_t m = 0; m < meshes.size(); ++m)
        for (const Vec3& p : meshes[m].positions) mesh_box[m].grow(p);
    bounds = Aabb{};
    for (size_t i = 0; i < instances.size(); ++i) {
        Instance& inst = instances[i];
        require(inst.mesh < meshes.size(), source + ": instance " + std::to_string(i) + " has no mesh");
        inst.prim_base = uint32_t(std::min<uint64_t>(total, std::numeric_limits<uint32_t>::max()));
        total += meshes[inst.mesh].triangle_count();
        require(total <= uint64_t(std::numeric_limits<int32_t>::max()),
                source + ": the scene places " + std::to_string(total) + "+ triangles by instance " +
                    std::to_string(i) + "; primitive ids are int32 (at most 2^31 - 1)");
        const Aabb& b = mesh_box[inst.mesh];
        if (b.empty()) continue;
        for (int c = 0; c < 8; ++c)
            bounds.grow(to_world(inst.object_to_world, Vec3(c & 1 ? b.hi.x : b.lo.x, c & 2 ? b.hi.y : b.lo.y,
                                                             c & 4 ? b.hi.z : b.lo.z)));
    }
    require(bounds.lo.x <= bounds.hi.x || total == 0, source + ": non-finite world bounds");
    placed_triangles = total;
    triangles.clear();
    tri_material.clear();
    tri_instance.clear();
}

uint32_t Scene::instance_of(uint32_t prim) const {
    if (flattened()) return tri_instance.at(prim);
    // The last instance whose prim_base <= prim and that places triangles.
    auto it = std::upper_bound(instances.begin(), instances.end(), prim,
                               [](uint32_t p, const Instance& inst) { return p < inst.prim_base; });
    require(it != instances.begin(), source + ": primitive " + std::to_string(prim) + " belongs to no instance");
    size_t i = size_t(it - instances.begin()) - 1;
    while (i > 0 && meshes[instances[i].mesh].triangle_count() == 0) --i;
    require(prim - instances[i].prim_base < meshes[instances[i].mesh].triangle_count(),
            source + ": primitive " + std::to_string(prim) + " belongs to no instance");
    return uint32_t(i);
}

Triangle Scene::world_triangle(uint32_t prim) const {
    if (flattened()) return triangles.at(prim);
    const Instance& inst = instances[instance_of(prim)];
    const Vec3* p = &meshes[inst.mesh].positions[3 * size_t(prim - inst.prim_base)];
    return Triangle{to_world(inst.object_to_world, p[0]), to_world(inst.object_to_world, p[1]),
                    to_world(inst.object_to_world, p[2])};
}

uint32_t Scene::material_of(uint32_t prim) const {
    if (flattened()) return tri_material.at(prim);
    const Instance& inst = instances[instance_of(prim)];
    return meshes[inst.mesh].materials[prim - inst.prim_base];
}

}  // namespace rtsim
