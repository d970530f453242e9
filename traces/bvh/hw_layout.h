#pragma once
// Hardware layout of the BVH: the one memory image the reference tracer and the SystemC model
// both read (DESIGN rule 3). Documented byte by byte in docs/bvh_layout.md.
//
// A binary BVH whose nodes hold the boxes of their two children, so one 64-byte fetch (one
// cache line) feeds one issue of a 2-wide ray-box pipeline (as in Aila & Laine 2009's layout).
#include <cstdint>
#include <vector>

#include "traces/common/aabb.h"

namespace rtsim {

/// child_count value of an unused child slot (only in the root of a one-leaf tree).
constexpr uint32_t kEmptyChild = 0xFFFFFFFFu;

struct HwNode {                 // 64 bytes, 64-byte aligned in memory
    float lo[2][3];             //  0: child 0 box min xyz, 12: child 1 box min xyz
    float hi[2][3];             // 24: child 0 box max xyz, 36: child 1 box max xyz
    uint32_t child_ref[2];      // 48: interior child: node index; leaf: first triangle index
    uint32_t child_count[2];    // 56: 0: interior child; kEmptyChild: no child; else leaf size
};
static_assert(sizeof(HwNode) == 64, "HwNode must be one 64-byte line");

/// HwTriangle::flags bits.
constexpr uint32_t kTriAnyHit = 1u << 0;         ///< alpha-MASK: call the any-hit (alpha) test
constexpr uint32_t kTriCoverageShift = 8;        ///< bits 8..15: alpha coverage x 255
constexpr uint32_t kTriMaterialShift = 16;       ///< bits 16..31: material index

struct HwTriangle {             // 48 bytes
    float v0[3];                //  0
    float v1[3];                // 12
    float v2[3];                // 24
    uint32_t prim;              // 36: stable primitive id (scene order, see scene.h)
    uint32_t inst;              // 40: instance id
    uint32_t flags;             // 44: kTriAnyHit | coverage << 8 | material << 16
};
static_assert(sizeof(HwTriangle) == 48, "HwTriangle must be 48 bytes");

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
