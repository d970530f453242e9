#include "traces/tracer/ray_trace.h"

#include <array>
#include <chrono>

#include "traces/common/error.h"
#include "traces/shading/materials.h"
#include "traces/tracer/wavefront.h"

namespace rtsim {

using nlohmann::json;

namespace {

/// The scene's plan for its model features (alpha mask, instancing), with the ray kinds replaced
/// by what the caller gave: every kind present is written, whatever the scene calls for.
WorkloadPlan given_rays_plan(const Scene& scene, const std::vector<PendingRay>& rays) {
    std::array<uint64_t, kRayKindCount> per_kind{};
    for (const PendingRay& r : rays) ++per_kind[size_t(r.kind)];
    std::vector<RayKind> present;
    for (int k = 0; k < kRayKindCount; ++k)
        if (per_kind[k]) present.push_back(RayKind(k));
    WorkloadPlan plan = plan_workload(scene, present);
    for (int k = 0; k < kRayKindCount; ++k) {
        plan.generate[k] = per_kind[k] > 0;
        for (Effect& e : plan.effects) {
            if (e.name != ray_kind_name(RayKind(k))) continue;
            e.simulated = per_kind[k] > 0;
            e.why = e.simulated ? std::to_string(per_kind[k]) + " rays given by the caller" : "none given";
        }
    }
    return plan;
}

}  // namespace

json write_ray_trace(const Scene& scene, const SceneLabel& label, const Accel& accel,
                     const std::vector<PendingRay>& rays, const RayTraceOptions& o, const ProgressFn& progress) {
    require(!o.out_dir.empty(), "no output folder given");
    require(!rays.empty(), "no rays given: a trace needs at least one ray");
    const auto t_start = std::chrono::steady_clock::now();
    const WorkloadPlan plan = given_rays_plan(scene, rays);

    TraceFolderWriter folder(o.out_dir, accel.image());
    // Given rays are one wavefront of independent rays (no parents), with the cones they carry.
    folder.set_shading(scene, build_shading_scene(scene, label.name, label.procedural, accel.image().end_address()));
    WavefrontResult res = trace_wavefront(accel, rays, o.threads, [&](uint64_t done) {
        if (progress) progress(done, rays.size(), "trace");
    });
    folder.add_wavefront(plan, rays, res);

    json extra = {{"workload",
                   {{"requested", "given"},
                    {"source", "rays given by the caller (rtsim.write_trace)"},
                    {"effects", effects_json(plan)}}}};
    return folder.finish(scene, label, accel.image(), 0.0, t_start, std::move(extra));
}

}  // namespace rtsim
