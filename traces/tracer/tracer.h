#pragma once
// The reference tracer's front door: scene in, trace folder out.
//   OUT/trace.rtt      rays, reference hits, per-ray work, BVH image (docs/trace_format.md)
//   OUT/manifest.json  scene, BVH parameters and SAH cost, workload and effects, counts
//   OUT/render.png     simple shading of the primary hits
// (Heatmaps of work per pixel are drawn from the trace by the Python package.)
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "traces/accel/accel.h"
#include "traces/common/ray.h"
#include "traces/scene/procedural.h"

namespace rtsim {

/// A camera given on the command line: eye, target, vertical field of view in degrees.
struct CameraOverride {
    Vec3 eye{0.0f};
    Vec3 target{0.0f, 0.0f, -1.0f};
    float yfov_degrees = 60.0f;
};

struct TraceOptions {
    std::string scene;    ///< .gltf/.glb path, or a procedural scene name ("cornell", ...)
    std::string out_dir;  ///< created if missing
    /// Ray kinds requested. Empty (the default): every kind the scene calls for. A list narrows
    /// it; listed kinds the scene does not call for are skipped, and the manifest says why.
    std::vector<RayKind> workload;
    uint32_t width = 320;
    uint32_t height = 240;
    uint32_t bounces = 1;  ///< diffuse bounce depth (and reflection/refraction depth)
    uint64_t seed = 1;
    std::optional<CameraOverride> camera;
    AccelOptions accel;  ///< which acceleration structure and builder (docs/accel.md)
    /// Trace an instanced scene (one that places some geometry more than once: shares_geometry())
    /// through one world-space structure of `accel.kind` instead of the default two levels: a
    /// BLAS of that kind per geometry and a TLAS over the instances (docs/accel.md, "Two-level
    /// structures"). No effect without instancing.
    bool flatten = false;
    ProceduralOptions procedural;
    unsigned threads = 0;  ///< 0: all hardware threads. Output does not depend on it.
    /// Animated frames (docs/accel.md, "Frames"): the instances move by the documented motion
    /// (traces/scene/scene_motion.h), deforming meshes take their animation's pose (a BLAS per
    /// frame, built or refitted by frame_policy), a TLAS per frame, and the workload is traced
    /// once per frame. Needs instancing or deforming geometry, traced two-level (not --flatten).
    uint32_t frames = 1;
    /// Moving scenes (docs/accel.md, "Moving scenes"): how each frame's structures follow the
    /// previous frame's (traces/accel/two_level/frame_policy.h): "rebuild", "refit", "adaptive".
    std::string frame_policy = "rebuild";
    /// adaptive: rebuild once a refitted tree's SAH cost exceeds this many times its rebuilt cost.
    double rebuild_threshold = 1.25;
    /// Lights added to a scene without any (traces/raygen/added_lights.h): "none" or "sun" (a
    /// directional light, so the scene's traces hold shadow rays; the manifest says so).
    std::string lights = "none";
    /// Reflection rays (traces/raygen/secondary.h): "mirror" (the ideal direction) or "glossy"
    /// (sampled from the GGX lobe of the material's glTF roughness; docs/raygen.md).
    std::string reflections = "mirror";
    /// Russian roulette on path rays: 0 off; N, each bounce past the first N continues with the
    /// surface's albedo as probability (bounces still caps the depth).
    uint32_t roulette_after = 0;
    /// The child order any-hit (shadow) rays are traced in, as traversal.anyhit_order names it:
    /// nearest (the default), largest_box or fixed. A trace in a run's order carries that walk's
    /// reference work, so the run checks it exactly (docs/accel.md, "Any-hit child order").
    std::string anyhit_order = "nearest";

    /// The options a caller chooses, each with its name and meaning (scene and out_dir aside):
    /// the Python bindings read the defaults and apply keyword arguments through this, so every
    /// default above is declared once, here (rtsim._core.trace_defaults()).
    template <class V>
    void visit(V& v) {
        v("workload", workload, "ray kinds (empty: every kind the scene calls for)");
        v("width", width, "camera image width: one primary ray per pixel");
        v("height", height, "camera image height");
        v("bounces", bounces, "depth of diffuse, reflection and refraction bounces");
        v("seed", seed, "seed of the random numbers (bounce directions, procedural scenes)");
        v("camera", camera, "(eye, target, vertical field of view in degrees); none: the scene's camera or a framing");
        v("accel", accel.kind, "acceleration structure (accel_kinds())");
        v("builder", accel.builder, "its builder; empty: the structure's default");
        v("build_settings", accel.settings, "{name: value} over the builder's documented settings (accel_kinds())");
        v("flatten", flatten, "instanced scenes: one world-space structure instead of two levels");
        v("hairball_triangles", procedural.hairball_triangles, "triangles of the built-in hairball");
        v("threads", threads, "tracing threads, 0 for all cores (the trace is the same for any)");
        v("frames", frames, "animated frames of an instanced or deforming scene");
        v("frame_policy", frame_policy, "each frame's structures: rebuild, refit or adaptive (docs/accel.md, Moving scenes)");
        v("rebuild_threshold", rebuild_threshold, "adaptive: rebuild once the refitted SAH cost exceeds this ratio");
        v("lights", lights, "lights added to a scene without any: none or sun (the manifest lists them)");
        v("reflections", reflections, "reflection rays: mirror, or glossy (a GGX lobe of the material's roughness)");
        v("roulette_after", roulette_after, "Russian roulette on path rays past this many bounces (0: off)");
        v("anyhit_order", anyhit_order, "any-hit rays' child order: nearest, largest_box or fixed (traversal.anyhit_order)");
    }
};

/// Progress callback: rays traced so far, rays expected (an estimate until the last wavefront),
/// and the stage ("load", "bvh", "primary", ...). Called from the calling thread only.
using ProgressFn = std::function<void(uint64_t done, uint64_t total, const std::string& stage)>;

/// Runs the whole pipeline and returns the manifest it wrote. Throws rtsim::Error on bad input.
nlohmann::json trace_scene(const TraceOptions& options, const ProgressFn& progress = {});

}  // namespace rtsim
