#include "traces/raygen/workload.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <glm/gtc/constants.hpp>

#include "traces/common/round_cone.h"
#include "traces/raygen/surface.h"

namespace rtsim {


namespace {

/// "3 materials (a, b, c)", naming at most four.
std::string count_names(const std::vector<std::string>& names, const char* noun) {
    std::ostringstream out;
    out << names.size() << " " << noun << (names.size() == 1 ? "" : "s");
    if (!names.empty()) {
        out << " (";
        for (size_t i = 0; i < names.size() && i < 4; ++i) out << (i ? ", " : "") << names[i];
        if (names.size() > 4) out << ", ...";
        out << ")";
    }
    return out.str();
}

std::string material_label(const Material& m, size_t index) {
    return m.name.empty() ? "material " + std::to_string(index) : m.name;
}

/// Materials used by at least one triangle, so unused entries do not trigger effects.
std::vector<bool> used_materials(const Scene& scene) {
    std::vector<bool> used(scene.materials.size(), false);
    std::vector<bool> placed(scene.meshes.size(), false);
    for (const Instance& inst : scene.instances) placed[inst.mesh] = true;
    for (size_t m = 0; m < scene.meshes.size(); ++m)
        if (placed[m])
            for (uint32_t id : scene.meshes[m].materials) used[id] = true;
    return used;
}

void plan_emissive(const Scene& scene, const std::vector<bool>& used, WorkloadPlan* plan) {
    double total = 0.0;
    std::vector<double> areas;
    // Emissive triangles in primitive-id order, flattened or not (placed meshes only).
    std::vector<std::vector<uint32_t>> in_mesh(scene.meshes.size());  // emissive triangles of each mesh
    for (size_t m = 0; m < scene.meshes.size(); ++m)
        for (size_t k = 0; k < scene.meshes[m].triangle_count(); ++k)
            if (scene.materials[scene.meshes[m].materials[k]].is_emissive()) in_mesh[m].push_back(uint32_t(k));
    std::vector<uint32_t> emissive;
    for (const Instance& inst : scene.instances)
        for (uint32_t k : in_mesh[inst.mesh]) emissive.push_back(inst.prim_base + k);
    std::sort(emissive.begin(), emissive.end());
    for (uint32_t i : emissive) {
        const Triangle t = scene.world_triangle(i);
        double area = scene.is_curved(i) ? curved_area(scene, i) : 0.5 * glm::length(glm::cross(t.v1 - t.v0, t.v2 - t.v0));
        if (!(area > 0.0)) continue;
        plan->emissive_prims.push_back(uint32_t(i));
        total += area;
        areas.push_back(total);
    }
    for (double a : areas) plan->emissive_cdf.push_back(float(a / total));
    if (!plan->emissive_cdf.empty()) plan->emissive_cdf.back() = 1.0f;
}

}  // namespace

bool material_reflects(const Material& m) { return m.metallic >= 0.5f || m.roughness <= 0.2f; }
bool material_refracts(const Material& m) { return m.transmission > 0.0f; }

WorkloadPlan plan_workload(const Scene& scene, const std::vector<RayKind>& requested) {
    WorkloadPlan plan;
    const bool scene_default = requested.empty();  // every kind the scene calls for
    auto asked = [&](RayKind k) {
        return scene_default || std::find(requested.begin(), requested.end(), k) != requested.end();
    };
    std::vector<bool> used = used_materials(scene);
    plan_emissive(scene, used, &plan);

    std::vector<std::string> reflective, transmissive, masked, emissive;
    for (size_t i = 0; i < scene.materials.size(); ++i) {
        if (!used[i]) continue;
        const Material& m = scene.materials[i];
        if (material_reflects(m)) reflective.push_back(material_label(m, i));
        if (material_refracts(m)) transmissive.push_back(material_label(m, i));
        if (m.alpha_mode == AlphaMode::mask) masked.push_back(material_label(m, i));
        if (m.is_emissive()) emissive.push_back(material_label(m, i));
    }
    plan.reflective_materials = uint32_t(reflective.size());
    plan.transmissive_materials = uint32_t(transmissive.size());

    // One entry per ray kind: called for by the scene? asked for by the user?
    auto decide = [&](RayKind kind, bool called_for, const std::string& because, const std::string& not_because) {
        Effect e{ray_kind_name(kind), false, ""};
        if (!asked(kind)) {
            e.why = "not requested" + (called_for ? " (the scene has " + because + ")" : "");
        } else if (!called_for) {
            e.why = scene_default ? not_because : "requested, but " + not_because;
        } else {
            e.simulated = true;
            e.why = because;
        }
        plan.generate[size_t(kind)] = e.simulated;
        plan.effects.push_back(e);
    };
    decide(RayKind::primary, true, "camera rays, one per pixel", "");
    std::string lights;
    if (!scene.lights.empty()) lights = std::to_string(scene.lights.size()) + " punctual light" + (scene.lights.size() == 1 ? "" : "s");
    if (!plan.emissive_prims.empty())
        lights += (lights.empty() ? "" : " and ") + std::to_string(plan.emissive_prims.size()) +
                  " emissive triangles of " + count_names(emissive, "material");
    decide(RayKind::shadow, !lights.empty(), lights, "the scene has no punctual light and no emissive material");
    decide(RayKind::reflection, !reflective.empty(), count_names(reflective, "metallic or smooth material"),
           "no material is metallic (>= 0.5) or smooth (roughness <= 0.2)");
    decide(RayKind::diffuse, true, "cosine-weighted bounces from every surface", "");
    decide(RayKind::refraction, !transmissive.empty(), count_names(transmissive, "transmissive material"),
           "no material has KHR_materials_transmission");

    // Model features the scene calls for (used by the SystemC model to instantiate blocks).
    plan.effects.push_back({"alpha_mask", !masked.empty(),
                            masked.empty() ? "no alphaMode MASK material"
                                           : count_names(masked, "MASK material") +
                                                 ": any-hit alpha test, stochastic by textureAlphaCoverage"});
    size_t meshes_used = scene.meshes.size();
    plan.effects.push_back({"instancing", false,
                            scene.uses_instancing()
                                ? std::to_string(scene.instances.size()) + " instances of " + std::to_string(meshes_used) +
                                      " meshes, flattened to one world-space structure (--flatten)"
                                : "every mesh is placed once"});
    return plan;
}

namespace {

/// A point on an emissive sphere or capsule, area-uniform as the triangles' (the far half is
/// shadowed by the light itself): a sphere's by (z, phi); a capsule's on its body or, in
/// proportion to their area, on its end caps (each the part of its end sphere beyond the body's
/// circle of contact). With k = (r1 - r0) / L the body's point for the swept sphere of centre
/// parameter s is that sphere's at n = -k axis + sqrt(1 - k^2) (cos phi, sin phi), and its area
/// grows with the radius r0 + k s: s is drawn with that density.
Vec3 curved_light_point(const Scene& scene, uint32_t prim, float u1, float u2) {
    const CurvedShape shape = scene.curved_shape(prim);
    const float r = shape.r0;
    auto on_sphere = [](float a, float b) {
        const float z = 1.0f - 2.0f * a, phi = 2.0f * glm::pi<float>() * b;
        const float ring = std::sqrt(std::max(0.0f, 1.0f - z * z));
        return Vec3(ring * std::cos(phi), ring * std::sin(phi), z);
    };
    if (!shape.capsule()) return shape.a + r * on_sphere(u1, u2);
    const Vec3 a = shape.a, b = shape.b;
    const float r0 = shape.r0, r1 = shape.r1, length = glm::length(b - a);
    if (end_sphere_holds_other(length, r0, r1)) return (r1 > r0 ? b : a) + std::max(r0, r1) * on_sphere(u1, u2);
    const Vec3 axis = (b - a) / length;
    Vec3 e1, e2;
    make_basis(axis, &e1, &e2);
    const float k = (r1 - r0) / length, c = std::sqrt(1.0f - k * k), phi = 2.0f * glm::pi<float>() * u2;
    const Vec3 ring = std::cos(phi) * e1 + std::sin(phi) * e2;
    const float band = (r0 + r1) * length * c * c / 2.0f, cap0 = r0 * r0 * (1.0f - k), cap1 = r1 * r1 * (1.0f + k);
    float u = u1 * (band + cap0 + cap1);  // in units of 2 pi
    if (u < band) {
        // s with density r0 + k s: the root of k s^2 / 2 + r0 s = u (L (r0 + r1) / 2) / band.
        const float area = u / band * length * (r0 + r1) / 2.0f;
        const float s = 2.0f * area / (r0 + std::sqrt(std::max(0.0f, r0 * r0 + 2.0f * k * area)));
        return a + s * axis + (r0 + k * s) * (-k * axis + c * ring);
    }
    u -= band;
    const bool at_a = u < cap0;
    // z = n.axis uniform over the cap: [-1, -k] at a, [-k, 1] at b.
    const float f = at_a ? u / cap0 : (u - cap0) / cap1;
    const float z = at_a ? -1.0f + f * (1.0f - k) : -k + f * (1.0f + k);
    const Vec3 n = z * axis + std::sqrt(std::max(0.0f, 1.0f - z * z)) * ring;
    return at_a ? a + r0 * n : b + r1 * n;
}

}  // namespace

std::vector<LightSample> light_samples(const Scene& scene, const WorkloadPlan& plan, float u0, float u1, float u2) {
    std::vector<LightSample> out;
    for (const Light& light : scene.lights) {
        LightSample s;
        if (light.type == LightType::directional) {
            s.direction = -glm::normalize(light.direction);
            s.at_infinity = true;
        } else {
            s.point = light.position;
        }
        out.push_back(s);
    }
    if (!plan.emissive_cdf.empty()) {
        size_t i = std::lower_bound(plan.emissive_cdf.begin(), plan.emissive_cdf.end(), u0) - plan.emissive_cdf.begin();
        i = std::min(i, plan.emissive_cdf.size() - 1);
        const uint32_t prim = plan.emissive_prims[i];
        const Triangle t = scene.world_triangle(prim);
        LightSample s;
        if (scene.is_curved(prim)) {
            s.point = curved_light_point(scene, prim, u1, u2);
        } else {
            // Uniform point on the triangle (square-root parameterisation).
            float su = std::sqrt(u1);
            float b1 = 1.0f - su, b2 = u2 * su;
            s.point = (1.0f - b1 - b2) * t.v0 + b1 * t.v1 + b2 * t.v2;
        }
        out.push_back(s);
    }
    return out;
}

}  // namespace rtsim
