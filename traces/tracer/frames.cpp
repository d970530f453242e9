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
    require(two_level, scene_path + ": --frames " + n + " animates instances, but the scene places no geometry "
                                    "more than once (no instancing, so nothing is traced two-level)");
}

AnimatedImage build_animated(const Scene& scene, const AccelOptions& options, uint32_t frames) {
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
    out.image = build_two_level_frames(scene, options, poses, &out.timing);
    out.image.build_ms = ms_since(t0);
    return out;
}

uint64_t frame_seed(uint64_t seed, uint32_t frame) {
    return frame == 0 ? seed : hash_combine(seed, 0x6672616d65ull /*"frame"*/, frame);
}

json frames_json(const AccelImage& image, const TwoLevelTiming& timing, const std::vector<uint64_t>& first_ray,
                 const std::vector<uint64_t>& rays) {
    json per_frame = json::array();
    const json& slices = image.params.at("frames");
    for (size_t f = 0; f < rays.size(); ++f)
        per_frame.push_back({{"frame", f},
                             {"first_ray", first_ray[f]},
                             {"rays", rays[f]},
                             {"tlas_nodes", slices[f]["tlas_count"]},
                             {"tlas_build_ms", timing.tlas_ms[f]}});
    return {{"count", rays.size()},
            {"motion", motion_description()},
            {"blas_build_ms", timing.blas_ms},
            {"per_frame", per_frame}};
}

}  // namespace rtsim
