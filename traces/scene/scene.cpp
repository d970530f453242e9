#include "traces/scene/scene.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <unordered_map>

#include "traces/common/error.h"
#include "traces/common/float_rounding.h"
#include "traces/common/round_cone.h"

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

CurvedShape placed_curved_shape(const Mesh& mesh, size_t prim, const Vec3& a, const Vec3& b, double scale) {
    CurvedShape s;
    s.a = a, s.b = b;
    s.r0 = float(double(mesh.radii[prim]) * scale);
    s.r1 = float(double(mesh.end_radius(prim)) * scale);
    if (a == b) s.r0 = s.r1 = std::max(s.r0, s.r1);
    return s;
}

double largest_axis_scale(const glm::dmat4& m) {
    double s = 0.0;
    for (int c = 0; c < 3; ++c) s = std::max(s, glm::length(glm::dvec3(m[c])));
    return s;
}

namespace {

bool finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// A sphere (p0 == p1) or capsule (p0 to p1, radii r0 and r1) as a flattened primitive: {lo, hi, centre}, its
/// box rounded outward so it holds the whole shape the records store (floats), the centre a
/// sphere's or the capsule's midpoint.
Triangle curved_primitive(const Vec3& p0, const Vec3& p1, float r0, float r1) {
    Triangle t;
    for (int a = 0; a < 3; ++a) {  // the swept sphere's box is its end spheres' boxes' union
        t.v0[a] = round_down(std::min(double(p0[a]) - double(r0), double(p1[a]) - double(r1)));
        t.v1[a] = round_up(std::max(double(p0[a]) + double(r0), double(p1[a]) + double(r1)));
    }
    t.v2 = p0 == p1 ? p0 : Vec3(0.5 * (glm::dvec3(p0) + glm::dvec3(p1)));
    return t;
}

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
    curved_radius.clear();
    curved_end_radius.clear();
    capsule_ends.clear();
    const bool curved = has_curved(), capsules = has_capsules();  // then a radius (ends) per primitive
    bool two_radii = false;
    for (const Mesh& m : meshes) two_radii = two_radii || !m.end_radii.empty();
    if (curved) curved_radius.reserve(total);
    if (two_radii) curved_end_radius.reserve(total);
    if (capsules) capsule_ends.reserve(total);
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
        // A sphere's radius scales with the transform's largest axis (a sphere under a
        // non-uniform scale stays a sphere: the one that bounds the ellipsoid).
        const double scale = mesh.radii.empty() ? 0.0 : largest_axis_scale(inst.object_to_world);
        for (size_t t = 0; t < mesh.triangle_count(); ++t) {
            Triangle tri{to_world(mesh.positions[3 * t]), to_world(mesh.positions[3 * t + 1]),
                         to_world(mesh.positions[3 * t + 2])};
            float radius = 0.0f, end_radius = 0.0f;
            const std::array<Vec3, 2> ends{tri.v0, tri.v1};
            if (mesh.is_curved(t)) {
                const CurvedShape shape = placed_curved_shape(mesh, t, ends[0], ends[1], scale);
                radius = shape.r0, end_radius = shape.r1;
                tri = curved_primitive(ends[0], ends[1], radius, end_radius);
                // A node scaled to 0 (how glTF hides nodes) leaves radius 0: never hit, as its
                // triangles would be.
                if (!(radius >= 0.0f) || !std::isfinite(radius) || !(end_radius >= 0.0f) || !std::isfinite(end_radius))
                    throw Error(source + ": mesh " + std::to_string(inst.mesh) + " '" + mesh.name + "' curved primitive " +
                                std::to_string(t) + (inst.node >= 0 ? " placed by node " + std::to_string(inst.node) : "") +
                                " has radius " + std::to_string(radius) + " in world space (beyond the float range)");
            }
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
            if (curved) curved_radius.push_back(radius);
            if (two_radii) curved_end_radius.push_back(end_radius);
            if (capsules) capsule_ends.push_back(mesh.is_capsule(t) ? ends : std::array<Vec3, 2>{tri.v2, tri.v2});
        }
    }
}

double curved_area(const Scene& scene, uint32_t prim) {
    constexpr double kPi = 3.14159265358979323846;
    const CurvedShape s = scene.curved_shape(prim);
    const double r0 = s.r0, r1 = s.r1, length = glm::length(glm::dvec3(s.b) - glm::dvec3(s.a));
    if (end_sphere_holds_other(length, r0, r1)) return 4.0 * kPi * std::max(r0, r1) * std::max(r0, r1);
    // With k = (r1 - r0) / L: the cone's band pi (r0 + r1) L (1 - k^2), and the caps beyond its
    // circles of contact, 2 pi r0^2 (1 - k) and 2 pi r1^2 (1 + k); 2 pi r L + 4 pi r^2 at k = 0.
    const double k = (r1 - r0) / length;
    return kPi * (r0 + r1) * length * (1.0 - k * k) + 2.0 * kPi * (r0 * r0 * (1.0 - k) + r1 * r1 * (1.0 + k));
}

namespace {

/// Spheres (capsules when `capsules`) the instances place, for a scene kept as instances.
size_t placed_curved(const Scene& scene, bool capsules) {
    std::vector<size_t> in_mesh(scene.meshes.size(), 0);
    for (size_t m = 0; m < scene.meshes.size(); ++m)
        for (size_t p = 0; p < scene.meshes[m].radii.size(); ++p)
            in_mesh[m] += scene.meshes[m].is_curved(p) && scene.meshes[m].is_capsule(p) == capsules ? 1 : 0;
    size_t n = 0;
    for (const Instance& inst : scene.instances) n += in_mesh[inst.mesh];
    return n;
}

}  // namespace

size_t Scene::sphere_count() const {
    if (!flattened()) return placed_curved(*this, false);
    size_t n = 0;
    for (uint32_t p = 0; p < curved_radius.size(); ++p) n += is_sphere(p) ? 1 : 0;
    return n;
}

size_t Scene::capsule_count() const {
    if (!flattened()) return placed_curved(*this, true);
    size_t n = 0;
    for (uint32_t p = 0; p < capsule_ends.size(); ++p) n += is_capsule(p) ? 1 : 0;
    return n;
}

bool Scene::has_curved() const {
    for (const Mesh& m : meshes)
        for (float r : m.radii)
            if (r > 0.0f) return true;
    return false;
}

bool Scene::has_capsules() const {
    for (const Mesh& m : meshes)
        for (size_t p = 0; p < m.radii.size(); ++p)
            if (m.is_capsule(p)) return true;
    return false;
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
