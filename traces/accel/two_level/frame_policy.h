#pragma once
// Per-frame structure policies for moving scenes (docs/accel.md, "Moving scenes"): how each
// frame's BLAS of a deforming mesh, and each frame's TLAS, is made from the previous frame's.
//
//   rebuild   every frame built afresh by the kind's builder (binned SAH, LBVH, ...)
//   refit     the first frame's tree kept, its boxes refitted to each frame's geometry
//             (traces/bvh/refit.h): cheap, valid for any motion, its quality falls as it moves
//   adaptive  refit while the refitted tree's SAH cost stays within `rebuild_threshold` times
//             the cost just after its last rebuild; the frame after it crosses is rebuilt (so
//             the decision needs no second build: the refit's own SAH cost decides)
//
// A driver makes the same choice per acceleration structure (DXR's ALLOW_UPDATE and
// PERFORM_UPDATE); the threshold rule follows Lauterbach et al. 2006 ("RT-DEFORM: interactive
// ray tracing of dynamic scenes using BVHs"), who rebuild when a refitted node's area has grown
// past a ratio of its area at the last rebuild, here applied to the whole tree's SAH cost.
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "traces/accel/accel.h"

namespace rtsim {

enum class FramePolicy : uint8_t { rebuild = 0, refit = 1, adaptive = 2 };

/// "rebuild", "refit", "adaptive".
const char* frame_policy_name(FramePolicy p);
/// Throws rtsim::Error listing the choices if `name` is none.
FramePolicy parse_frame_policy(const std::string& name);

struct FramePolicyOptions {
    FramePolicy policy = FramePolicy::rebuild;
    /// adaptive: rebuild once the refitted SAH cost exceeds this many times the rebuilt one's.
    double rebuild_threshold = 1.25;
};

/// One structure (a deforming mesh's BLAS, or the TLAS) followed over frames.
class FrameTree {
public:
    explicit FrameTree(FramePolicyOptions options) : m_options(options) {}
    /// What frame `frame` does with this structure: frame 0 always builds; later frames by the
    /// policy and the last refit's SAH ratio. Call before the frame's build, then done().
    bool rebuilds(uint32_t frame) const;
    /// The reuse to pass in AccelOptions::tree_reuse for this frame's build (rebuilds(): none).
    TreeReuse* reuse_for(uint32_t frame);
    /// After the frame's build (with reuse_for's reuse): records its SAH cost (the image's own
    /// where its boxes are not the tree's: TreeReuse::image_sah_cost); returns the frame's record
    /// {"action": "build"|"refit", "tree_nodes", "sah_cost", "sah_ratio"}.
    nlohmann::json done(const BuildConfig& config);

private:
    FramePolicyOptions m_options;
    TreeReuse m_reuse;
    double m_rebuilt_cost = 0.0;  ///< SAH cost just after the last rebuild
    double m_ratio = 1.0;         ///< last frame's SAH cost over m_rebuilt_cost
    bool m_rebuilt = true;        ///< the last frame rebuilt
};

}  // namespace rtsim
