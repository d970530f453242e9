#pragma once
// The adaptive octree's hardware layout (docs/accel.md, "octree"), byte by byte:
//
//   region "nodes"      OctNode, 16 bytes (below); an interior node's non-empty children are
//                       consecutive, in child order, from the index it names
//   region "prim_refs"  uint32_t, 4 bytes: an index into "triangles"; a leaf's list contiguous,
//                       in increasing order
//   region "triangles"  HwTriangle, 48 bytes, each scene triangle once, in scene order
//
// A cell is cut at its centre into 8 children: child c = x + 2y + 4z, bit a set for the upper half
// of axis a. The root cell is the scene's box (params "bounds"), not a cube: each axis is halved
// where it has extent; an axis of zero extent is not cut (its centre coordinate is the cell's upper
// bound, and children on its upper side are empty). A traversal unit carries a pending cell as a
// 32-byte stack entry: node index, tnear, and the distances to the cell's six planes (the
// parameters of Revelles et al. 2000).
#include <cstdint>
#include <cstring>

#include "traces/common/record_layout.h"

namespace rtsim {

struct OctNode {       // 16 bytes
    uint32_t word0;    // 0: bits 0-7: child mask (bit c: child c is stored; 0: this is a leaf);
                       //    bits 8-31: interior: index of the first stored child
    uint32_t word1;    // 4: interior: centre x (f32 bits); leaf: first entry in prim_refs
    uint32_t word2;    // 8: interior: centre y (f32 bits); leaf: references listed
    uint32_t word3;    // 12: interior: centre z (f32 bits); leaf: 0

    static constexpr uint32_t kIndexBits = 24;
    static constexpr uint32_t kMaxIndex = (1u << kIndexBits) - 1;

    bool leaf() const { return (word0 & 0xFFu) == 0; }
    uint32_t mask() const { return word0 & 0xFFu; }
    uint32_t first_child() const { return word0 >> 8; }
    /// Index of stored child c (its bit must be set).
    uint32_t child(uint32_t c) const { return first_child() + uint32_t(__builtin_popcount(mask() & ((1u << c) - 1u))); }
    float centre(int axis) const {
        float f;
        std::memcpy(&f, axis == 0 ? &word1 : axis == 1 ? &word2 : &word3, sizeof f);
        return f;
    }
    uint32_t first_ref() const { return word1; }
    uint32_t ref_count() const { return word2; }
    /// A leaf's reserved bits (word0's index bits and word3): 0 in every image the builder makes.
    uint32_t leaf_reserved() const { return word0 | word3; }

    static OctNode interior(uint32_t mask, uint32_t first_child, const float centre[3]) {
        OctNode n{mask | first_child << 8, 0, 0, 0};
        std::memcpy(&n.word1, &centre[0], 4);
        std::memcpy(&n.word2, &centre[1], 4);
        std::memcpy(&n.word3, &centre[2], 4);
        return n;
    }
    static OctNode make_leaf(uint32_t first, uint32_t count) { return OctNode{0, first, count, 0}; }
};
static_assert(sizeof(OctNode) == 16, "OctNode must be 16 bytes");
inline RecordLayout layout_of(const OctNode*) {
    return {RTSIM_FIELD(OctNode, word0), RTSIM_FIELD(OctNode, word1), RTSIM_FIELD(OctNode, word2), RTSIM_FIELD(OctNode, word3)};
}

/// Bytes of an octree traversal stack entry in hardware: node, tnear, six plane distances.
constexpr uint32_t kOctStackEntryBytes = 32;
/// Deepest octree an image may hold.
constexpr uint32_t kOctMaxDepth = 20;
/// Stack entries a ray can need: up to 7 pending siblings per level.
constexpr uint32_t kOctMaxStack = 7 * kOctMaxDepth;

/// The adaptive octree builder's settings.
struct OctreeConfig {
    /// A cell listing more references than this is subdivided (until max_depth). Smaller: deeper
    /// trees, more references, fewer triangle tests per leaf.
    uint32_t max_leaf_size = 8;
    /// Deepest subdivision: cells are at least 2^-max_depth of the scene per axis (16 resolves a
    /// teapot of 1/10,000 of its stadium into cells of about 1/7 of its size).
    uint32_t max_depth = 16;
    /// Triangles are clipped to the child cells (a triangle is listed where its part has extent);
    /// false: listed in every child its box overlaps.
    bool clip = true;

    /// The settings as data (traces/accel/build_settings.h).
    template <class V>
    void visit(V& v) {
        v.field("max_leaf_size", max_leaf_size, "references", "A cell listing more references is subdivided", 1, 1024);
        v.field("max_depth", max_depth, "levels", "Deepest subdivision", 1, kOctMaxDepth);
        v.flag("clip", clip, "Triangles clipped to the child cells (false: listed wherever their box overlaps)");
    }
};

}  // namespace rtsim
