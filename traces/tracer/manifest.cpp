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
            {"triangles", scene.triangle_count()},
            {"meshes", scene.meshes.size()},
            {"instances", scene.instances.size()},
            {"uses_instancing", scene.uses_instancing()},
            {"lights", scene.lights.size()},
            {"cameras", scene.cameras.size()},
            {"bounds", {{"lo", vec(scene.bounds.lo)}, {"hi", vec(scene.bounds.hi)}}},
            {"materials", materials},
            {"warnings", scene.warnings}};
}

json bvh_json(const HwBvh& bvh, const BuildConfig& c) {
    const BvhStats& s = bvh.stats;
    return {{"builder", "binned_sah"},
            {"config",
             {{"bins", c.bins},
              {"traversal_cost", c.traversal_cost},
              {"intersection_cost", c.intersection_cost},
              {"max_leaf_size", c.max_leaf_size},
              {"max_depth", c.max_depth}}},
            {"layout", {{"node_bytes", sizeof(HwNode)}, {"triangle_bytes", sizeof(HwTriangle)}, {"arity", 2}}},
            {"nodes", s.nodes},
            {"leaves", s.leaves},
            {"max_depth", s.max_depth},
            {"avg_leaf_size", s.avg_leaf_size},
            {"max_leaf_size", s.max_leaf_size},
            {"sah_cost", s.sah_cost},
            {"build_ms", s.build_ms},
            {"bytes", bvh.nodes.size() * sizeof(HwNode) + bvh.triangles.size() * sizeof(HwTriangle)}};
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
    k.nodes += w.nodes;
    k.box_tests += w.box_tests;
    k.tri_tests += w.tri_tests;
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
                                            {"nodes_per_ray", k.nodes / n},
                                            {"box_tests_per_ray", k.box_tests / n},
                                            {"tri_tests_per_ray", k.tri_tests / n},
                                            {"anyhit_calls_per_ray", k.anyhit_calls / n}};
    }
    return {{"rays", m_written}, {"rejected", m_rejected}, {"by_kind", kinds}};
}

}  // namespace rtsim
