// Per-frame structure policies (frame_policy.h).
#include "traces/accel/two_level/frame_policy.h"

#include "traces/bvh/refit.h"
#include "traces/common/error.h"

namespace rtsim {

const char* frame_policy_name(FramePolicy p) {
    switch (p) {
        case FramePolicy::rebuild: return "rebuild";
        case FramePolicy::refit: return "refit";
        case FramePolicy::adaptive: return "adaptive";
    }
    return "?";
}

FramePolicy parse_frame_policy(const std::string& name) {
    for (FramePolicy p : {FramePolicy::rebuild, FramePolicy::refit, FramePolicy::adaptive})
        if (name == frame_policy_name(p)) return p;
    throw Error("frame policy '" + name + "' is unknown (choose rebuild, refit or adaptive)");
}

bool FrameTree::rebuilds(uint32_t frame) const {
    if (frame == 0) return true;
    switch (m_options.policy) {
        case FramePolicy::rebuild: return true;
        case FramePolicy::refit: return false;
        case FramePolicy::adaptive: return m_ratio > m_options.rebuild_threshold;
    }
    return true;
}

TreeReuse* FrameTree::reuse_for(uint32_t frame) {
    m_rebuilt = rebuilds(frame);
    if (m_rebuilt) m_reuse.refit_from.reset();
    else {
        require(m_reuse.built != nullptr, "frame policy " + std::string(frame_policy_name(m_options.policy)) +
                                              ": the structure keeps no binary tree to refit (frame " +
                                              std::to_string(frame) + "); use --frame-policy rebuild, or a kind "
                                              "that refits (bvh2, bvh4-8, cwbvh6/8, bih, bkd)");
        m_reuse.refit_from = m_reuse.built;
    }
    return &m_reuse;
}

nlohmann::json FrameTree::done(const BuildConfig& config) {
    // A kind built without a binary tree (kd-tree, grid, octree, GK-BVH) only rebuilds: no cost.
    if (!m_reuse.built) return {{"action", "build"}, {"tree_nodes", nullptr}, {"sah_cost", nullptr}, {"sah_ratio", nullptr}};
    // The structure's own boxes where they are not the tree's (oriented ones age as a refit
    // keeps their rotations), else the tree's.
    const double cost = m_reuse.image_sah_cost > 0.0 ? m_reuse.image_sah_cost : sah_cost(*m_reuse.built, config);
    m_reuse.image_sah_cost = 0.0;  // the next frame's build sets its own
    if (m_rebuilt) m_rebuilt_cost = cost;
    m_ratio = m_rebuilt_cost > 0.0 ? cost / m_rebuilt_cost : 1.0;
    return {{"action", m_rebuilt ? "build" : "refit"},
            {"tree_nodes", m_reuse.built->nodes.size()},
            {"sah_cost", cost},
            {"sah_ratio", m_ratio}};
}

}  // namespace rtsim
