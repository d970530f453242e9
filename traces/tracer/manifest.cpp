#include "traces/tracer/manifest.h"

#include <cmath>

namespace rtsim {

using nlohmann::json;

namespace {
json vec(const Vec3& v) { return json::array({v.x, v.y, v.z}); }
const char* alpha_mode_name(AlphaMode m) {
    return m == AlphaMode::mask ? "MASK" : m == AlphaMode::blend ? "BLEND" : "OPAQUE";
}
}  // namespace

json scene_json(const Scene& scene, const std::string& name, bool procedural) {
    json materials = json::array();
    for (const Material& m : scene.materials)
        materials.push_back({{"name", m.name}, {"metallic", m.metallic}, {"roughness", m.roughness},
                             {"alpha_mode", alpha_mode_name(m.alpha_mode)}, {"alpha_coverage", m.alpha_coverage},
                             {"transmission", m.transmission}, {"emissive", m.is_emissive()}});
    return {{"name", name},
            {"source", scene.source},
            {"procedural", procedural},
            {"triangles", scene.triangle_count() - scene.sphere_count() - scene.capsule_count()},
            {"spheres", scene.sphere_count()},
            {"capsules", scene.capsule_count()},
            {"meshes", scene.meshes.size()},
            {"instances", scene.instances.size()},
            {"uses_instancing", scene.uses_instancing()},
            {"lights", scene.lights.size()},
            {"cameras", scene.cameras.size()},
            {"bounds", {{"lo", vec(scene.bounds.lo)}, {"hi", vec(scene.bounds.hi)}}},
            {"materials", materials},
            {"warnings", scene.warnings}};
}

json accel_json(const AccelImage& image) {
    json j = image.stats;
    j["kind"] = image.kind;
    // Every kind records these (docs/accel.md); null where a kind has no such thing (a grid has
    // no branching width and no SAH cost).
    for (const char* key : {"builder", "width", "node_bytes", "sah_cost"})
        if (!j.contains(key)) j[key] = nullptr;
    j["footprint_bytes"] = image.footprint_bytes();
    j["build_ms"] = image.build_ms;
    json regions = json::array();
    for (const Region& r : image.regions)
        regions.push_back({{"name", r.name}, {"kind", data_kind_name(r.kind)}, {"record_bytes", r.record_bytes},
                           {"count", r.count}, {"bytes", r.size_bytes()}});
    j["regions"] = regions;
    return j;
}

json camera_json(const Camera& c, const std::string& source) {
    return {{"source", source},
            {"eye", vec(c.eye)},
            {"forward", vec(c.forward)},
            {"up", vec(c.up)},
            {"yfov_degrees", c.yfov * 180.0 / 3.14159265358979}};
}

json effects_json(const WorkloadPlan& plan) {
    json out = json::array();
    for (const Effect& e : plan.effects) out.push_back({{"name", e.name}, {"simulated", e.simulated}, {"why", e.why}});
    return out;
}

void RayCounts::add(RayKind kind, uint16_t depth, const Hit& hit, const WorkCounts& w, bool written) {
    KindStats& k = m_kinds[size_t(kind)];
    ++k.rays;
    k.hits += hit.valid();
    k.written += written;
    k.steps += w.steps;
    k.box_tests += w.box_tests;
    k.tri_tests += w.tri_tests;
    k.sphere_tests += w.sphere_tests;
    k.capsule_tests += w.capsule_tests;
    k.anyhit_calls += w.anyhit_calls;
    k.max_depth = std::max(k.max_depth, depth);
    m_written += written;
}

json RayCounts::to_json() const {
    json kinds = json::object();
    for (int i = 0; i < kRayKindCount; ++i) {
        const KindStats& k = m_kinds[i];
        if (!k.rays) continue;
        double n = double(k.rays);
        kinds[ray_kind_name(RayKind(i))] = {{"traced", k.rays},
                                            {"written", k.written},
                                            {"hits", k.hits},
                                            {"hit_rate", k.hits / n},
                                            {"max_depth", k.max_depth},
                                            {"steps_per_ray", k.steps / n},
                                            {"box_tests_per_ray", k.box_tests / n},
                                            {"tri_tests_per_ray", k.tri_tests / n},
                                            {"sphere_tests_per_ray", k.sphere_tests / n},
                                            {"capsule_tests_per_ray", k.capsule_tests / n},
                                            {"anyhit_calls_per_ray", k.anyhit_calls / n}};
    }
    return {{"rays", m_written}, {"rejected", m_rejected}, {"by_kind", kinds}};
}

}  // namespace rtsim
