#pragma once
// The kd-tree's hardware layout (docs/accel.md, "kdtree"), documented byte by byte:
//
//   region "nodes"      KdNode, 8 bytes (below), depth first: a node's below child is the next
//                       node, its above child is named in the node (pbrt's KdAccelNode layout)
//   region "prim_refs"  uint32_t, 4 bytes: an index into "triangles"; a leaf's list contiguous,
//                       in increasing order; leaves' lists in node order
//   region "triangles"  HwTriangle, 48 bytes, each scene triangle once, in scene order
//
// The cells are implicit: the root cell is the box in the image's params ("bounds", exact
// floats), and each split halves a cell at its plane. A traversal unit holds the root box in
// registers and carries each pending cell as a 12-byte stack entry (node index, tnear, tfar).
#include <cstdint>
#include <cstring>

#include "traces/common/record_layout.h"

namespace rtsim {

struct KdNode {        // 8 bytes
    uint32_t word0;    // 0: interior: the split plane's position (f32 bits); leaf: first entry in prim_refs
    uint32_t word1;    // 4: bits 0-1: split axis (0 x, 1 y, 2 z) or 3 for a leaf;
                       //    bits 2-31: interior: index of the above child; leaf: references listed

    static constexpr uint32_t kLeaf = 3;
    static constexpr uint32_t kIndexBits = 30;
    static constexpr uint32_t kMaxIndex = (1u << kIndexBits) - 1;  ///< largest child index or list length

    bool leaf() const { return (word1 & 3u) == kLeaf; }
    int axis() const { return int(word1 & 3u); }
    float split() const {
        float f;
        std::memcpy(&f, &word0, sizeof f);
        return f;
    }
    uint32_t above() const { return word1 >> 2; }
    uint32_t first_ref() const { return word0; }
    uint32_t ref_count() const { return word1 >> 2; }
    /// A leaf has no reserved bits (both words are used).
    uint32_t leaf_reserved() const { return 0; }

    static KdNode interior(int axis, float split, uint32_t above) {
        KdNode n;
        std::memcpy(&n.word0, &split, sizeof split);
        n.word1 = uint32_t(axis) | above << 2;
        return n;
    }
    static KdNode make_leaf(uint32_t first, uint32_t count) { return KdNode{first, kLeaf | count << 2}; }
};
static_assert(sizeof(KdNode) == 8, "KdNode must be 8 bytes");
inline RecordLayout layout_of(const KdNode*) {
    return {RTSIM_FIELD(KdNode, word0), RTSIM_FIELD(KdNode, word1)};
}

/// Bytes of a kd-tree traversal stack entry in hardware: node index, tnear, tfar.
constexpr uint32_t kKdStackEntryBytes = 12;
/// Deepest kd-tree an image may hold (the stepper's stack; one entry per level at most).
constexpr uint32_t kKdMaxDepth = 64;

/// The kd-tree builder's settings (Wald & Havran 2006, "On building fast kd-trees for ray
/// tracing, and on doing that in O(N log N)"). Every field: what it does and what it costs.
struct KdConfig {
    /// SAH cost of traversing an interior node, K_T (the paper's 15). Higher: shallower trees,
    /// bigger leaves, fewer steps and more triangle tests per ray.
    float traversal_cost = 15.0f;
    /// SAH cost of one ray/triangle test, K_I (the paper's 20). A node becomes a leaf when no split
    /// is cheaper than K_I x its references.
    float intersection_cost = 20.0f;
    /// Empty-space bonus: a split with an empty side costs (1 - empty_bonus) x its SAH cost (the
    /// paper's lambda = 0.8, i.e. 0.2). Higher: more empty cells cut off around geometry; deeper
    /// trees, more nodes, fewer triangle tests.
    float empty_bonus = 0.2f;
    /// Deepest tree; 0: 8 + 1.3 log2 N (pbrt's rule), at most 64 (the traversal stack).
    uint32_t max_depth = 0;
    /// Perfect splits: a triangle straddling a split is clipped to each child cell and its clipped
    /// part's box gives the child's candidate planes and decides where it is listed. false: its
    /// box is merely cut at the plane (cheaper builds, more references).
    bool clip = true;

    /// The settings as data (traces/accel/build_settings.h).
    template <class V>
    void visit(V& v) {
        v.field("traversal_cost", traversal_cost, "K_T", "SAH cost of traversing an interior node", 0.001, 1e6);
        v.field("intersection_cost", intersection_cost, "K_I", "SAH cost of one ray/triangle test", 0.001, 1e6);
        v.field("empty_bonus", empty_bonus, "fraction", "A split with an empty side costs (1 - empty_bonus) x its SAH cost", 0, 0.99);
        v.field("max_depth", max_depth, "levels", "Deepest tree; 0: 8 + 1.3 log2 N", 0, kKdMaxDepth);
        v.flag("clip", clip, "Perfect splits: straddling triangles clipped to each child cell (false: their boxes cut)");
    }
};

}  // namespace rtsim
