// Scenes kept as instances (scene.h, index_instances()): primitive ids, bounds and per-primitive
// lookups without a flattened triangle list, for two-level tracing.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

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
    curved_radius.clear();  // no flattened primitives (curved_shape() computes them)
    curved_end_radius.clear();
    capsule_ends.clear();
    uint64_t total = 0;
    std::vector<Aabb> mesh_box(meshes.size());
    curved_meshes = false;
    for (size_t m = 0; m < meshes.size(); ++m) {
        const Mesh& mesh = meshes[m];
        curved_meshes = curved_meshes || !mesh.radii.empty();
        for (size_t k = 0; k < mesh.positions.size(); ++k) {
            const size_t prim = k / 3;
            const float r = mesh.is_curved(prim) ? std::max(mesh.radii[prim], mesh.end_radius(prim)) : 0.0f;
            mesh_box[m].grow(mesh.positions[k] - Vec3(r));  // a curved primitive's end spheres
            mesh_box[m].grow(mesh.positions[k] + Vec3(r));
        }
    }
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

bool Scene::placed_is_curved(uint32_t prim, bool capsule) const {
    const Instance& inst = instances[instance_of(prim)];
    const Mesh& mesh = meshes[inst.mesh];
    const size_t local = prim - inst.prim_base;
    return capsule ? mesh.is_capsule(local) : mesh.is_curved(local);
}

CurvedShape Scene::curved_shape(uint32_t prim) const {
    if (flattened()) {
        CurvedShape s;
        s.r0 = curved_radius[prim];
        s.r1 = end_radius(prim);
        s.a = s.b = sphere_centre(triangles[prim]);
        if (is_capsule(prim)) s.a = capsule_ends[prim][0], s.b = capsule_ends[prim][1];
        return s;
    }
    const Instance& inst = instances[instance_of(prim)];
    const Mesh& mesh = meshes[inst.mesh];
    const size_t local = prim - inst.prim_base;
    const glm::dmat4& m = inst.object_to_world;
    return placed_curved_shape(mesh, local, to_world(m, mesh.positions[3 * local]),
                               to_world(m, mesh.positions[3 * local + 1]), largest_axis_scale(m));
}

uint32_t Scene::material_of(uint32_t prim) const {
    if (flattened()) return tri_material.at(prim);
    const Instance& inst = instances[instance_of(prim)];
    return meshes[inst.mesh].materials[prim - inst.prim_base];
}


namespace {

/// "node 4" or "node 4 (EXT_mesh_gpu_instancing entry 2)" for instance i.
std::string instance_name(const Scene& scene, size_t i) {
    const int32_t node = scene.instances[i].node;
    if (node < 0) return "instance " + std::to_string(i);
    size_t entry = 0, entries = 0;
    for (size_t k = 0; k < scene.instances.size(); ++k)
        if (scene.instances[k].node == node) {
            entry += k < i ? 1 : 0;
            ++entries;
        }
    std::string name = "node " + std::to_string(node);
    return entries > 1 ? name + " (EXT_mesh_gpu_instancing entry " + std::to_string(entry) + ")" : name;
}

/// A nonzero (or overflowing: huge, not collapsed) normal in single precision.
bool has_area(const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 n = glm::cross(b - a, c - a);
    return n.x != 0.0f || n.y != 0.0f || n.z != 0.0f;
}

/// True if one of the first few triangles of the instance's mesh that have an area in object
/// space keeps it in world space (rounded to float as flatten() rounds), or leaves the float
/// range (not a collapse: flatten() names that triangle).
bool keeps_area(const Scene& scene, const Instance& inst, bool* mesh_has_area) {
    const Mesh& mesh = scene.meshes[inst.mesh];
    int tried = 0;
    for (size_t t = 0; t < mesh.triangle_count() && tried < 16; ++t) {
        const Vec3* p = &mesh.positions[3 * t];
        if (!has_area(p[0], p[1], p[2])) continue;
        *mesh_has_area = true;
        ++tried;
        const Vec3 a = to_world(inst.object_to_world, p[0]), b = to_world(inst.object_to_world, p[1]),
                   c = to_world(inst.object_to_world, p[2]);
        if (!std::isfinite(a.x + a.y + a.z + b.x + b.y + b.z + c.x + c.y + c.z) || has_area(a, b, c)) return true;
    }
    return false;
}

}  // namespace

void check_curved_similarity(const Scene& scene, size_t instance, const glm::dmat4& m, const std::string& when) {
    const Mesh& mesh = scene.meshes[scene.instances[instance].mesh];
    require(mesh.radii.empty() || is_similarity(m),
            scene.source + ": " + instance_name(scene, instance) + when + " places mesh '" + mesh.name +
                "' of spheres or capsules under a non-uniform scale or a shear; a two-level structure traces them "
                "in object space, where that makes ellipsoids (a flattened scene takes the bounding sphere): scale "
                "the node uniformly, or trace with --flatten");
}

bool is_similarity(const glm::dmat4& m) {
    const glm::dvec3 c[3] = {glm::dvec3(m[0]), glm::dvec3(m[1]), glm::dvec3(m[2])};
    const double s = glm::length(c[0]), tol = 1e-5 * s * s;
    for (int i = 0; i < 3; ++i)
        for (int j = i; j < 3; ++j)
            if (std::fabs(glm::dot(c[i], c[j]) - (i == j ? s * s : 0.0)) > tol) return false;
    return true;
}

void check_instance_transforms(const Scene& scene, bool invertible) {
    int first_collapsed = -1;
    bool area_anywhere = false;
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const glm::dmat4& m = scene.instances[i].object_to_world;
        bool finite = true;
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) finite = finite && std::isfinite(m[c][r]);
        require(finite, scene.source + ": " + instance_name(scene, i) +
                            " has a non-finite transform (NaN or infinite in its matrix, translation, "
                            "rotation or scale, or in a parent's)");
        if (invertible) {
            const glm::dmat4 inv = glm::inverse(m);
            bool ok = glm::determinant(glm::dmat3(m)) != 0.0;
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r) ok = ok && std::isfinite(float(inv[c][r]));
            require(ok, scene.source + ": " + instance_name(scene, i) +
                            " has a singular transform (a scale of 0 or a degenerate matrix), which a "
                            "two-level structure cannot invert; fix the node's scale or matrix, or trace "
                            "with --flatten");
        }
        if (invertible) check_curved_similarity(scene, i, m, "");
        if (area_anywhere && !invertible) continue;
        bool mesh_area = false;
        if (keeps_area(scene, scene.instances[i], &mesh_area)) area_anywhere = true;
        else if (mesh_area && first_collapsed < 0) first_collapsed = int(i);
    }
    if (area_anywhere || first_collapsed < 0) return;
    const glm::dmat4& m = scene.instances[size_t(first_collapsed)].object_to_world;
    char det[32];
    std::snprintf(det, sizeof det, "%g", glm::determinant(glm::dmat3(m)));
    throw Error(scene.source + ": every triangle collapses to zero area in world space (" +
                instance_name(scene, size_t(first_collapsed)) + "'s transform has determinant " + det +
                ": a scale of 0 or 1e-30, or a matrix of zeros); no ray could hit the scene. Fix the "
                "nodes' scale or matrix");
}

}  // namespace rtsim
