#pragma once
// The B-Kd tree's hardware layout (Woop, Marmitt & Slusallek 2006, "B-KD trees for hardware
// accelerated ray tracing of dynamic scenes", Graphics Hardware; docs/accel.md, "bkd"), byte by
// byte:
//
//   region "nodes"      BkdNode, 20 bytes (below); a node's two children are adjacent, the first
//                       one named in the node
//   region "triangles"  HwTriangle, 48 bytes, in leaf order: every scene triangle stored exactly
//                       once (no references, no duplicates)
//
// A bounded kd-tree: an interior node splits on one axis and bounds each child by an interval on
// it, [lo0, hi0] for the first child and [lo1, hi1] for the second (the intervals may overlap or
// leave gaps). A child's cell is its parent's cut by its two planes; the root cell is the box in
// the image's params ("bounds"). A BIH node (bih_layout.h) stores only the inner two of these
// four planes, so a B-Kd child's cell is never larger than the BIH's on the same tree, at 8 bytes
// more per node and two more plane tests per step. Woop et al. give a node two intervals, an axis
// and a child reference; the 20-byte packing here (no pad to 24 or 32) is this project's choice.
// Pending cells are 12-byte stack entries (node, tnear, tfar), as in the kd-tree and BIH.
#include <cstdint>
#include <cstring>

#include "traces/common/record_layout.h"

namespace rtsim {

struct BkdNode {         // 20 bytes
    uint32_t word0;      // 0: bits 0-1: split axis (0 x, 1 y, 2 z) or 3 for a leaf;
                         //    bits 2-31: interior: index of the first child (the second is next);
                         //    leaf: its first triangle
    uint32_t plane[4];   // 4: interior: lo0, hi0, lo1, hi1 (f32 bits): child 0 spans [lo0, hi0] on
                         //    the axis, child 1 [lo1, hi1]; leaf: plane[0] = triangles, the rest 0

    static constexpr uint32_t kLeaf = 3;
    static constexpr uint32_t kMaxIndex = (1u << 30) - 1;

    bool leaf() const { return (word0 & 3u) == kLeaf; }
    int axis() const { return int(word0 & 3u); }
    uint32_t left() const { return word0 >> 2; }
    uint32_t first() const { return word0 >> 2; }
    uint32_t count() const { return plane[0]; }
    /// Child `side`'s interval end: lo (end 0) or hi (end 1).
    float bound(int side, int end) const {
        float f;
        std::memcpy(&f, &plane[2 * side + end], sizeof f);
        return f;
    }
    static BkdNode interior(int axis, uint32_t left, float lo0, float hi0, float lo1, float hi1) {
        BkdNode n{uint32_t(axis) | left << 2, {0, 0, 0, 0}};
        const float p[4] = {lo0, hi0, lo1, hi1};
        std::memcpy(n.plane, p, sizeof p);
        return n;
    }
    static BkdNode make_leaf(uint32_t first, uint32_t count) { return BkdNode{kLeaf | first << 2, {count, 0, 0, 0}}; }
};
static_assert(sizeof(BkdNode) == 20, "BkdNode must be 20 bytes");
inline RecordLayout layout_of(const BkdNode*) {
    return {RTSIM_FIELD(BkdNode, word0), RTSIM_FIELD(BkdNode, plane)};
}

/// Bytes of a B-Kd traversal stack entry in hardware: node index, tnear, tfar.
constexpr uint32_t kBkdStackEntryBytes = 12;
/// Deepest B-Kd tree an image may hold (the stepper's stack: one entry per level at most).
constexpr uint32_t kBkdMaxDepth = 64;

}  // namespace rtsim
