#pragma once
// The build-time wide BVH: a binary build tree (traces/bvh/build_tree.h, any builder, including
// trees whose leaves reference duplicated primitives) collapsed into nodes of up to `width`
// children. The fp32 wide layouts (wide_layout.h) and the compressed ones (traces/accel/cwbvh/)
// are serialised from this one tree, so a compressed BVH and its fp32 twin of the same width
// have the same topology and differ only by quantisation (docs/accel.md, "Wide BVHs").
#include <cstdint>
#include <vector>

#include "traces/bvh/build_tree.h"
#include "traces/bvh/config.h"

namespace rtsim {

/// Widest node any wide layout holds.
constexpr int kMaxWideWidth = 8;
/// Most triangles in one wide leaf: the compressed layouts encode a leaf's size in 3 unary bits
/// (Ylitie, Karras & Laine 2017, section 3.3); the fp32 layouts use the same limit so that each
/// has the topology of its compressed twin.
constexpr uint32_t kWideLeafMax = 3;

struct WideBuildChild {
    Aabb box;            ///< exact bounds of the child (the binary build node's box)
    uint32_t node = 0;   ///< interior child: index into WideBuildTree::nodes
    uint32_t first = 0;  ///< leaf: first entry in WideBuildTree::prims
    uint32_t count = 0;  ///< 0: interior; else the leaf's triangle count
    bool is_leaf() const { return count != 0; }
};

struct WideBuildNode {
    Aabb box;                          ///< union of the children
    uint32_t count = 0;                ///< children in child[0, count)
    WideBuildChild child[kMaxWideWidth];
    /// Slot of child i in the hardware node (identity unless assign_octant_slots() ran).
    uint8_t slot[kMaxWideWidth] = {0, 1, 2, 3, 4, 5, 6, 7};
};

/// Node 0 is the root (always interior, even over a single leaf). prims holds the scene
/// primitive ids of every leaf (a primitive may appear in several leaves of a spatial-split tree).
struct WideBuildTree {
    int width = 0;
    std::vector<WideBuildNode> nodes;
    std::vector<uint32_t> prims;
};

/// How the binary tree's nodes are grouped into wide nodes.
enum class Collapse : uint8_t {
    /// SAH-optimal over all collapses of the binary tree (Ylitie, Karras & Laine 2017, section 3.1).
    dp = 0,
    /// Greedy: open the child of largest surface area until the node is full (Wald, Benthin &
    /// Boulos 2008, "Getting rid of packets"; Ernst & Greiner 2008).
    greedy = 1,
};

struct CollapseConfig {
    /// Children per wide node, 2..8.
    int width = 8;
    /// Most triangles per leaf (<= kWideLeafMax); binary leaves above it are split first.
    uint32_t leaf_max = kWideLeafMax;
    Collapse method = Collapse::dp;
    /// SAH constants (C_t per node visit, C_i per triangle test), as in BuildConfig.
    float traversal_cost = 1.0f;
    float intersection_cost = 1.0f;
};

/// Splits every leaf of more than `leaf_max` triangles into a binary subtree at the object median
/// of the triangle centroids on the leaf's widest centroid axis, each piece's box being its
/// triangles' bounds clipped to the leaf's box (a spatial-split leaf stays inside its box).
BuildTree split_large_leaves(const BuildTree& tree, const std::vector<Triangle>& triangles, uint32_t leaf_max);
/// The same, reusing a tree the caller no longer needs (no copy of its arrays).
BuildTree split_large_leaves(BuildTree&& tree, const std::vector<Triangle>& triangles, uint32_t leaf_max);

/// Collapses a binary build tree (leaves of at most config.leaf_max triangles: call
/// split_large_leaves first) into a wide tree. Deterministic.
WideBuildTree collapse_tree(const BuildTree& tree, const CollapseConfig& config);

/// SAH cost of a wide tree, relative to the root's area: C_t per node, C_i per triangle, each
/// weighted by its box's area (the formula sah_cost() applies to the binary BVH).
double wide_sah_cost(const WideBuildTree& tree, float traversal_cost, float intersection_cost);

/// Assigns each node's children to slots as Ylitie et al. 2017 (section 3.2) do for octant-order
/// traversal: slot s should hold the child a ray of octant s meets first. Children go to the
/// slot minimising dot(child centroid - node centroid, direction of octant s), greedily by
/// increasing cost (the paper solves the assignment with an auction algorithm). Needs width 8.
void assign_octant_slots(WideBuildTree& tree);

/// The order a hardware layout stores a wide tree in. Nodes: the interior children of a node get
/// consecutive indices in slot order (the compressed layouts address them as base + rank), and
/// blocks are laid out depth first (a child always after its parent). Triangles: the leaves of a
/// node are consecutive, in slot order, nodes in storage order.
struct WideOrder {
    std::vector<uint32_t> stored;      ///< build node of each stored node
    std::vector<uint32_t> index;       ///< stored index of each build node
    std::vector<uint32_t> leaf_first;  ///< per build node * 8 + child: first stored triangle of a leaf
    std::vector<uint32_t> prims;       ///< scene primitive of each stored triangle
    std::vector<uint32_t> leaf_starts; ///< first stored triangle of every leaf, in storage order
};
WideOrder wide_order(const WideBuildTree& tree);

/// Shape statistics of a wide tree (the image's build stats).
struct WideShape {
    uint32_t leaves = 0, max_depth = 0, max_leaf_size = 0;
    double avg_leaf_size = 0.0, avg_children = 0.0;
};
WideShape wide_shape(const WideBuildTree& tree);

/// Throws rtsim::Error naming the first broken invariant: a child box outside its node's box,
/// a node with no or too many children, a leaf above leaf_max, an interior child not after its
/// parent or referenced twice, a prim range out of bounds, slots not a set of distinct indices.
void check_wide_tree(const WideBuildTree& tree, uint32_t leaf_max);

}  // namespace rtsim
