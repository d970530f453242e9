#pragma once
// The rays the Embree oracle test and the benchmark trace: primary rays from the automatic
// framing camera, one diffuse bounce from their hits (the tracer's own generator), and shadow-like
// rays from the primary hits to a point light placed in the upper middle of the scene (Sponza has
// no lights; the light only exists for these comparisons).
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "traces/bvh/hw_layout.h"
#include "traces/common/ray.h"
#include "traces/accel/bvh2/bvh2.h"
#include "traces/raygen/auto_framing.h"
#include "traces/raygen/camera.h"
#include "traces/raygen/secondary.h"
#include "traces/raygen/surface.h"
#include "traces/raygen/workload.h"
#include "traces/scene/gltf_loader.h"
#include "traces/scene/procedural.h"
#include "traces/scene/scene.h"

namespace rtsim::oracle {

/// Shadow rays stop this far short of the light (t = 1 at the light), as the tracer's.
constexpr float kShadowTmax = 1.0f - 1e-4f;

struct RaySets {
    std::vector<Ray> primary;  ///< one per pixel, closest hit
    std::vector<Ray> diffuse;  ///< one per primary hit, closest hit
    std::vector<Ray> shadow;   ///< one per primary hit facing the light, any hit
    Vec3 light{0.0f};
    std::string camera_why;
};

/// A scene by name: a built-in procedural scene (written as glTF under dir) or a glTF path.
inline Scene load_named_scene(const std::string& name, const std::string& dir,
                              const ProceduralOptions& options = {}) {
    if (is_procedural_scene(name)) {
        std::filesystem::create_directories(dir);
        return load_gltf(write_procedural_scene(name, dir, options));
    }
    return load_gltf(name);
}

/// The point light: horizontally centred, at 80% of the scene's height (in Sponza: the upper
/// middle of the atrium, below the open roof).
inline Vec3 oracle_light(const Scene& scene) {
    const Aabb& b = scene.bounds;
    return Vec3(b.center().x, b.lo.y + 0.8f * (b.hi.y - b.lo.y), b.center().z);
}

inline RaySets make_ray_sets(const Scene& scene, const HwBvh& bvh, uint32_t width, uint32_t height,
                             uint64_t seed = 1) {
    RaySets sets;
    const Bvh2Accel accel(bvh2_image(bvh, BuildConfig{}, "binned"), "oracle rays");
    const Camera cam = auto_frame(scene, accel, float(width) / float(height), &sets.camera_why);
    const PinholeCamera pin = make_camera(cam, width, height);
    const WorkloadPlan plan = plan_workload(scene, {RayKind::diffuse});
    const SpawnContext ctx{&scene, &plan, 1, seed};
    sets.light = oracle_light(scene);
    std::vector<PendingRay> spawned;
    for (uint32_t y = 0; y < height; ++y)
        for (uint32_t x = 0; x < width; ++x) {
            PendingRay p;
            p.ray = primary_ray(pin, x, y, width, height);
            p.pixel = y * width + x;
            sets.primary.push_back(p.ray);
            const Hit hit = trace_ray(bvh, p.ray, TraversalMode::closest_hit);
            if (!hit.valid()) continue;
            // Diffuse bounce through the tracer's generator (only the diffuse kind is planned).
            spawned.clear();
            spawn_secondaries(ctx, p, hit, p.pixel, &spawned);
            for (const PendingRay& s : spawned)
                if (s.kind == RayKind::diffuse) sets.diffuse.push_back(s.ray);
            // Shadow-like ray to the light, unnormalised direction (t = 1 at the light).
            const SurfacePoint sp = surface_point(scene, p.ray, hit);
            const Vec3 towards = sets.light - sp.position;
            if (!(glm::dot(sp.normal, towards) > 0.0f)) continue;
            Ray r;
            r.origin = offset_ray_origin(sp, towards);
            r.direction = sets.light - r.origin;
            r.tmin = 0.0f;
            r.tmax = kShadowTmax;
            if (ray_is_valid(r)) sets.shadow.push_back(r);
        }
    return sets;
}

}  // namespace rtsim::oracle
