#pragma once
// Hardware layout of the BVH: the one memory image the reference tracer and the SystemC model
// both read (docs/architecture.md, rule 3). Documented byte by byte in docs/bvh_layout.md.
//
// A binary BVH whose nodes hold the boxes of their two children, so one 64-byte fetch (one
// cache line) feeds one issue of a 2-wide ray-box pipeline (as in Aila & Laine 2009's layout).
#include <cstdint>
#include <vector>

#include "traces/common/aabb.h"
#include "traces/common/hw_triangle.h"
#include "traces/common/record_layout.h"

namespace rtsim {

/// child_count value of an unused child slot (only in the root of a one-leaf tree).
constexpr uint32_t kEmptyChild = 0xFFFFFFFFu;

struct alignas(64) HwNode {     // 64 bytes, 64-byte aligned in memory (one line per fetch)
    /// Both child boxes, one axis per 16 bytes so one 4-lane operation covers an axis of both
    /// children: bounds[axis][0 = min, 1 = max][child], axis a at offset 16 * a.
    float bounds[3][2][2];      //  0: x, 16: y, 32: z, each {min c0, min c1, max c0, max c1}
    uint32_t child_ref[2];      // 48: interior child: node index; leaf: first triangle index
    uint32_t child_count[2];    // 56: 0: interior child; kEmptyChild: no child; else leaf size

    float lo(int child, int axis) const { return bounds[axis][0][child]; }
    float hi(int child, int axis) const { return bounds[axis][1][child]; }
    float& lo(int child, int axis) { return bounds[axis][0][child]; }
    float& hi(int child, int axis) { return bounds[axis][1][child]; }
};
static_assert(sizeof(HwNode) == 64, "HwNode must be one 64-byte line");
inline RecordLayout layout_of(const HwNode*) {
    return {RTSIM_FIELD(HwNode, bounds), RTSIM_FIELD(HwNode, child_ref), RTSIM_FIELD(HwNode, child_count)};
}

/// Statistics of a built BVH (written to the trace manifest).
struct BvhStats {
    uint32_t nodes = 0;         ///< interior HwNodes
    uint32_t leaves = 0;
    uint32_t max_depth = 0;     ///< root at depth 0
    double avg_leaf_size = 0.0;
    uint32_t max_leaf_size = 0;
    double sah_cost = 0.0;      ///< SAH cost of the tree, relative to the root's area
    double build_ms = 0.0;      ///< wall time of the build (binning + flattening)
};

/// The flattened BVH: node 0 is the root. triangles are in leaf order (a permutation of the
/// scene's primitives; HwTriangle::prim gives the original id).
struct HwBvh {
    std::vector<HwNode> nodes;
    std::vector<HwTriangle> triangles;
    Aabb bounds;
    BvhStats stats;
};

}  // namespace rtsim
