#pragma once
// Secondary rays spawned at the hit of a path ray (primary, reflection, refraction or diffuse):
// shadow rays to the lights, a mirror or glossy (GGX) reflection, a refraction, a cosine-weighted
// diffuse bounce, each only if the plan generates that kind; past `roulette_after` bounces each
// path ray survives Russian roulette or is not spawned. Random numbers come from (seed, pixel, depth, slot)
// so the result does not depend on thread count or order.
#include <cstdint>
#include <vector>

#include "traces/common/ray.h"
#include "traces/raygen/workload.h"
#include "traces/scene/scene.h"

namespace rtsim {

struct PendingRay {
    Ray ray;
    RayKind kind = RayKind::primary;
    uint32_t pixel = 0;
    uint16_t depth = 0;
    bool any_hit = false;
    float shade = 0.0f;  ///< shadow rays: cosine at the surface (for the preview render)
    int64_t parent = -1;  ///< index of the parent in the previous wavefront, -1 for primary rays
    float cone_width = 0.0f, cone_spread = 0.0f;  ///< ray cone (traces/shading/texels.h)
};

struct SpawnContext {
    const Scene* scene;
    const WorkloadPlan* plan;
    uint32_t bounces;  ///< path rays deeper than this are not spawned
    uint64_t seed;
    /// Reflection rays sampled from the material's GGX lobe instead of the mirror direction.
    bool glossy = false;
    /// Russian roulette: a path ray spawned past this depth (0: never) survives with the
    /// surface's albedo as probability (roulette_survival).
    uint32_t roulette_after = 0;
};

/// Probability a path ray leaving a surface of `m` survives Russian roulette: the largest
/// component of its base colour (its albedo), kept within [0.05, 0.95] so no path is certain
/// to end or to go on (the clamp pbrt-v4 and most path tracers use in some form).
float roulette_survival(const Material& m);

/// Appends the secondaries of `parent` (which hit `hit`) to out; `index` is the parent's position
/// in its wavefront, used only to decorrelate random numbers.
void spawn_secondaries(const SpawnContext& ctx, const PendingRay& parent, const Hit& hit, uint64_t index,
                       std::vector<PendingRay>* out);

}  // namespace rtsim
