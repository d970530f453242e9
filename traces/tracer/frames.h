#pragma once
// Animated frames for the tracer (docs/accel.md, "Frames"): the checks on `--frames`, the
// multi-frame two-level build over the documented motion (traces/scene/scene_motion.h), the
// per-frame seed and the manifest's "frames" block.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "traces/accel/accel.h"
#include "traces/accel/two_level/two_level.h"
#include "traces/scene/scene_motion.h"

namespace rtsim {

/// Throws rtsim::Error naming `scene_path` unless `frames` can be traced: 1, or 2..kMaxFrames
/// on a scene traced two-level (it places some geometry more than once or deforms, and not
/// --flatten).
void check_frames(uint32_t frames, bool flatten, bool two_level, const std::string& scene_path);
/// True when some mesh an instance places deforms over frames (Scene::animation).
bool has_deforming_geometry(const Scene& scene);
constexpr uint32_t kMaxFrames = 1024;

/// The image of `frames` frames of the scene (kept as instances) and the motion that posed them.
struct AnimatedImage {
    AccelImage image;
    SceneMotion motion;
    TwoLevelTiming timing;
};
/// Deforming meshes (Scene::animation) get a BLAS per frame by `policy` (frame_policy.h).
AnimatedImage build_animated(const Scene& scene, const AccelOptions& options, uint32_t frames,
                             const FramePolicyOptions& policy = {});

/// Poses frame f for shading and secondary rays: the instances by `motion` and the deforming
/// meshes by the scene's animation (their positions replaced).
void pose_frame(Scene& scene, const SceneMotion& motion, uint32_t frame);

/// Seed of frame f's random numbers: the trace's seed for frame 0 (so frame 0 is the one-frame
/// trace), a hash of (seed, f) after it.
uint64_t frame_seed(uint64_t seed, uint32_t frame);

/// The manifest's "frames": count, motion, BLAS build time, and per frame its rays and TLAS
/// build time (`first_ray[f]`, `rays[f]` as written to FRMS; `image` the animated one).
nlohmann::json frames_json(const AccelImage& image, const TwoLevelTiming& timing,
                           const std::vector<uint64_t>& first_ray, const std::vector<uint64_t>& rays,
                           const Scene& scene, const FramePolicyOptions& policy);

}  // namespace rtsim
