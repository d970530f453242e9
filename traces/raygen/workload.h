#pragma once
// Which ray kinds and model features a scene calls for (docs/architecture.md, rule 10). The plan records, for
// every effect, whether it is simulated and why, in words a user can check against the scene.
#include <array>
#include <string>
#include <vector>

#include "traces/common/ray.h"
#include "traces/scene/scene.h"

namespace rtsim {

struct Effect {
    std::string name;  ///< "primary", "shadow", ..., "alpha_mask", "instancing"
    bool simulated = false;
    std::string why;
};

/// A light that shadow rays are aimed at: punctual, or a triangle of an emissive material.
struct LightSample {
    Vec3 point;      ///< position (point/spot, or a point on an emissive triangle)
    Vec3 direction;  ///< for directional lights: direction towards the light (unit)
    bool at_infinity = false;
};

struct WorkloadPlan {
    std::array<bool, kRayKindCount> generate{};  ///< ray kinds to generate and write
    std::vector<Effect> effects;
    std::vector<uint32_t> emissive_prims;  ///< emissive triangles, sampled by area
    std::vector<float> emissive_cdf;       ///< cumulative area over emissive_prims, last = 1
    uint32_t reflective_materials = 0;
    uint32_t transmissive_materials = 0;
    bool wants(RayKind kind) const { return generate[size_t(kind)]; }
};

/// Derives the plan from the scene and the kinds the user asked for. An empty request is the
/// default: every kind the scene calls for (primary and diffuse always; shadow, reflection and
/// refraction when lights, metallic or smooth, transmissive materials are present). An explicit
/// request narrows it: asked-for kinds the scene does not call for are dropped with the reason,
/// kinds not asked for are listed as such.
WorkloadPlan plan_workload(const Scene& scene, const std::vector<RayKind>& requested);

/// A surface sends reflection rays when it is metallic or smooth.
bool material_reflects(const Material& m);
/// A surface sends refraction rays when it transmits light.
bool material_refracts(const Material& m);

/// Points shadow rays from a surface point aim at: every punctual light, plus one sample on the
/// emissive surfaces (chosen by area from the random numbers u0..u2).
std::vector<LightSample> light_samples(const Scene& scene, const WorkloadPlan& plan, float u0,
                                       float u1, float u2);

}  // namespace rtsim
