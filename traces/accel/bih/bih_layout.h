#pragma once
// The bounding interval hierarchy's hardware layout (Wachter & Keller 2006, "Instant ray tracing:
// the bounding interval hierarchy", EGSR; docs/accel.md, "bih"), byte by byte:
//
//   region "nodes"      BihNode, 12 bytes (below); a node's two children are adjacent, the left
//                       one named in the node
//   region "triangles"  HwTriangle, 48 bytes, in leaf order: a leaf's triangles are contiguous and
//                       every scene triangle is stored exactly once (no references, no duplicates)
//
// An interior node holds two clip planes on one axis: the left child's triangles all lie at or
// below clip[0], the right child's at or above clip[1] (the planes may overlap or leave a gap
// between them). A child's cell is its parent's cut by its clip plane; the root cell is the box
// in the image's params ("bounds"). A traversal unit carries pending cells as 12-byte stack
// entries (node, tnear, tfar), as a kd-tree's.
#include <cstdint>
#include <cstring>

#include "traces/common/record_layout.h"

namespace rtsim {

struct BihNode {       // 12 bytes
    uint32_t word0;    // 0: bits 0-1: clip axis (0 x, 1 y, 2 z) or 3 for a leaf;
                       //    bits 2-31: interior: index of the left child (the right one is next);
                       //    leaf: its first triangle
    uint32_t word1;    // 4: interior: clip[0] (f32 bits), the left child's upper bound; leaf: triangles
    uint32_t word2;    // 8: interior: clip[1] (f32 bits), the right child's lower bound; leaf: 0

    static constexpr uint32_t kLeaf = 3;
    static constexpr uint32_t kMaxIndex = (1u << 30) - 1;

    bool leaf() const { return (word0 & 3u) == kLeaf; }
    int axis() const { return int(word0 & 3u); }
    uint32_t left() const { return word0 >> 2; }
    uint32_t first() const { return word0 >> 2; }
    uint32_t count() const { return word1; }
    float clip(int side) const {
        float f;
        std::memcpy(&f, side == 0 ? &word1 : &word2, sizeof f);
        return f;
    }
    static BihNode interior(int axis, uint32_t left, float clip0, float clip1) {
        BihNode n{uint32_t(axis) | left << 2, 0, 0};
        std::memcpy(&n.word1, &clip0, sizeof clip0);
        std::memcpy(&n.word2, &clip1, sizeof clip1);
        return n;
    }
    static BihNode make_leaf(uint32_t first, uint32_t count) { return BihNode{kLeaf | first << 2, count, 0}; }
};
static_assert(sizeof(BihNode) == 12, "BihNode must be 12 bytes");
inline RecordLayout layout_of(const BihNode*) {
    return {RTSIM_FIELD(BihNode, word0), RTSIM_FIELD(BihNode, word1), RTSIM_FIELD(BihNode, word2)};
}

/// Bytes of a BIH traversal stack entry in hardware: node index, tnear, tfar.
constexpr uint32_t kBihStackEntryBytes = 12;
/// Deepest BIH an image may hold (the stepper's stack: one entry per level at most).
constexpr uint32_t kBihMaxDepth = 64;

/// The Wachter & Keller builder's settings.
struct BihConfig {
    /// Largest leaf. Smaller: deeper trees, more node steps, fewer triangle tests.
    uint32_t max_leaf_size = 4;
    /// Deepest tree (splits at the median of the range where the split planes would go deeper).
    uint32_t max_depth = 64;

    /// The settings as data (traces/accel/build_settings.h).
    template <class V>
    void visit(V& v) {
        v.field("max_leaf_size", max_leaf_size, "triangles", "Largest leaf", 1, 64);
        v.field("max_depth", max_depth, "levels", "Deepest tree (median splits where the planes would go deeper)", 16, kBihMaxDepth);
    }
};

}  // namespace rtsim
