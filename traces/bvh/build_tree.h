#pragma once
// The build-time BVH: a plain binary tree the builders produce and flatten_bvh() turns into the
// hardware layout (hw_layout.h). Kept separate, as pbrt-v4 separates BVHBuildNode from
// LinearBVHNode, so other builders (or a test's median split) can feed the same flattener.
#include <cstdint>
#include <vector>

#include "traces/bvh/config.h"
#include "traces/bvh/hw_layout.h"
#include "traces/scene/scene.h"

namespace rtsim {

struct BuildNode {
    Aabb box;
    uint32_t first = 0;  // leaf: first slot in BuildTree::prim_ids; interior: left child index
    uint32_t count = 0;  // leaf: primitive count (> 0); interior: 0 (right child is first + 1)
    bool is_leaf() const { return count != 0; }
};

/// Node 0 is the root; children are allocated in adjacent pairs. Leaves own disjoint ranges of
/// prim_ids, a permutation of 0..N-1, laid out left subtree before right subtree.
struct BuildTree {
    std::vector<BuildNode> nodes;
    std::vector<uint32_t> prim_ids;
};

/// Binned SAH build (Wald 2007, "On fast construction of SAH-based bounding volume
/// hierarchies") over the triangles. Throws rtsim::Error on a non-finite vertex or when
/// config.max_depth cannot hold the tree.
BuildTree build_binned_sah(const std::vector<Triangle>& triangles, const BuildConfig& config);

/// Flattens a build tree into the hardware layout (node 0 an interior root, depth-first order,
/// triangles in leaf order) and fills the stats other than build_ms.
HwBvh flatten_bvh(const BuildTree& tree, const Scene& scene, const BuildConfig& config);

/// The hardware triangle record of scene primitive `prim` (vertices, ids, alpha and material
/// flags). Throws rtsim::Error if its material index does not fit the layout.
HwTriangle make_hw_triangle(const Scene& scene, uint32_t prim);

/// Levels of object-median splits needed below a node of `count` primitives before every leaf
/// holds at most max_leaf_size: ceil(log2(ceil(count / max_leaf_size))).
uint32_t median_levels_needed(uint32_t count, uint32_t max_leaf_size);

}  // namespace rtsim
