// Animated frames for the tracer (frames.h).
#include "traces/tracer/frames.h"

#include <chrono>

#include "traces/common/error.h"
#include "traces/common/rng.h"
#include "traces/common/stopwatch.h"

namespace rtsim {

using nlohmann::json;

void check_frames(uint32_t frames, bool flatten, bool two_level, const std::string& scene_path) {
    const std::string n = std::to_string(frames);
    require(frames >= 1 && frames <= kMaxFrames, "frames " + n + " is out of range (1.." + std::to_string(kMaxFrames) + ")");
    if (frames == 1) return;
    require(!flatten, scene_path + ": --frames " + n + " animates instances through a TLAS rebuilt each frame; "
                                   "--flatten traces one world-space structure instead (drop --flatten)");
    require(two_level, scene_path + ": --frames " + n + " animates instances and deforming meshes, but the scene "
                                    "places no geometry more than once and nothing in it deforms (no skin, morph "
                                    "target or procedural motion)");
}

bool has_deforming_geometry(const Scene& scene) {
    if (!scene.animation) return false;
    for (const Instance& inst : scene.instances)
        if (inst.mesh < scene.meshes.size() && scene.meshes[inst.mesh].triangle_count() &&
            scene.animation->deforms(inst.mesh))
            return true;
    return false;
}

AnimatedImage build_animated(const Scene& scene, const AccelOptions& options, uint32_t frames,
                             const FramePolicyOptions& policy) {
    const auto t0 = std::chrono::steady_clock::now();
    // Shared geometry moves (scene_motion.h): meshes whose geometry class is placed twice or more.
    const std::vector<uint32_t> cls = geometry_classes(scene);
    std::vector<uint32_t> uses(scene.meshes.size(), 0);
    for (const Instance& inst : scene.instances) ++uses[cls[inst.mesh]];
    std::vector<bool> moving(scene.meshes.size());
    for (size_t m = 0; m < scene.meshes.size(); ++m) moving[m] = uses[cls[m]] > 1;

    AnimatedImage out;
    out.motion = scene_motion(scene, moving);
    std::vector<std::vector<glm::dmat4>> poses(frames);
    for (uint32_t f = 0; f < frames; ++f)
        for (uint32_t i = 0; i < scene.instances.size(); ++i) poses[f].push_back(animated_transform(out.motion, i, f));
    out.image = build_two_level_frames(scene, options, poses, &out.timing, {scene.animation.get(), policy});
    out.image.build_ms = ms_since(t0);
    return out;
}

void pose_frame(Scene& scene, const SceneMotion& motion, uint32_t frame) {
    if (scene.animation)
        for (uint32_t m = 0; m < scene.meshes.size(); ++m)
            if (scene.meshes[m].triangle_count() && scene.animation->deforms(m))
                scene.animation->pose(m, frame, &scene.meshes[m].positions);
    pose_scene(scene, motion, frame);  // re-indexes: world bounds over the posed meshes
}

uint64_t frame_seed(uint64_t seed, uint32_t frame) {
    return frame == 0 ? seed : hash_combine(seed, 0x6672616d65ull /*"frame"*/, frame);
}

json frames_json(const AccelImage& image, const TwoLevelTiming& timing, const std::vector<uint64_t>& first_ray,
                 const std::vector<uint64_t>& rays, const Scene& scene, const FramePolicyOptions& policy) {
    json per_frame = json::array();
    const json& slices = image.params.at("frames");
    for (size_t f = 0; f < rays.size(); ++f)
        per_frame.push_back({{"frame", f},
                             {"first_ray", first_ray[f]},
                             {"rays", rays[f]},
                             {"tlas_nodes", slices[f]["tlas_count"]},
                             {"tlas_build_ms", timing.tlas_ms[f]},
                             {"blas_build_ms", f == 0 ? timing.blas_ms
                                               : f - 1 < timing.blas_frame_ms.size() ? timing.blas_frame_ms[f - 1] : 0.0},
                             {"build", slices[f].value("build", json::object())}});
    json out = {{"count", rays.size()},
                {"motion", motion_description()},
                {"blas_build_ms", timing.blas_ms},
                {"policy", frame_policy_name(policy.policy)},
                {"per_frame", per_frame}};
    if (policy.policy == FramePolicy::adaptive) out["rebuild_threshold"] = policy.rebuild_threshold;
    if (has_deforming_geometry(scene)) out["deformation"] = scene.animation->description();
    return out;
}

}  // namespace rtsim
