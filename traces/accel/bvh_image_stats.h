#pragma once
// The build statistics every BVH image reports (the manifest's "accel" keys, docs/accel.md): the
// builder, its SAH settings and the tree's shape, written once for the binary and wide kinds.
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "traces/bvh/config.h"
#include "traces/bvh/hw_layout.h"
#include "traces/common/hw_triangle.h"

namespace rtsim {

/// Builder, SAH settings, width, record sizes and the shape in `s` (its build_ms is not used:
/// images are deterministic, build time is the image's own field).
inline nlohmann::json bvh_image_stats(const BvhStats& s, const BuildConfig& c, const std::string& builder, int width,
                                      uint32_t node_bytes) {
    return {{"builder", builder},
            {"config",
             {{"bins", c.bins},
              {"traversal_cost", c.traversal_cost},
              {"intersection_cost", c.intersection_cost},
              {"max_leaf_size", c.max_leaf_size},
              {"max_depth", c.max_depth}}},
            {"width", width},
            {"node_bytes", node_bytes},
            {"triangle_bytes", sizeof(HwTriangle)},
            {"nodes", s.nodes},
            {"leaves", s.leaves},
            {"max_depth", s.max_depth},
            {"avg_leaf_size", s.avg_leaf_size},
            {"max_leaf_size", s.max_leaf_size},
            {"sah_cost", s.sah_cost}};
}

}  // namespace rtsim
