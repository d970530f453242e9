#pragma once
// The build-time BVH: a plain binary tree the builders produce and flatten_bvh() turns into the
// hardware layout (hw_layout.h). Kept separate, as pbrt-v4 separates BVHBuildNode from
// LinearBVHNode, so other builders (or a test's median split) can feed the same flattener.
#include <cstdint>
#include <vector>

#include "traces/bvh/config.h"
#include "traces/bvh/hw_layout.h"
#include "traces/common/huge_pages.h"
#include "traces/scene/scene.h"

namespace rtsim {

struct BuildNode {
    Aabb box;
    uint32_t first = 0;  // leaf: first slot in BuildTree::prim_ids; interior: left child index
    uint32_t count = 0;  // leaf: primitive count (> 0); interior: 0 (right child is first + 1)
    bool is_leaf() const { return count != 0; }
};

/// A build's nodes (16 MB on Sponza, written node after node and read back by parent index): on
/// huge pages, like the references they are built from.
using BuildNodes = std::vector<BuildNode, HugePageAllocator<BuildNode>>;

/// Node 0 is the root; children are allocated in adjacent pairs. Leaves own disjoint ranges of
/// prim_ids, laid out left subtree before right subtree. The binned builder's prim_ids are a
/// permutation of 0..N-1; the SBVH builder's (sbvh_builder.h) hold every primitive at least once
/// and may repeat one in several leaves (spatial splits): a converter must give each entry its
/// own triangle record (flatten_bvh does) and never assume prim_ids.size() == N.
struct BuildTree {
    BuildNodes nodes;
    std::vector<uint32_t> prim_ids;
};

/// Binned SAH build (Wald 2007, "On fast construction of SAH-based bounding volume
/// hierarchies") over the triangles, on `threads` threads (1: this one; the tree is the same,
/// node for node, for any count). Throws rtsim::Error on a non-finite vertex or when
/// config.max_depth cannot hold the tree.
BuildTree build_binned_sah(const std::vector<Triangle>& triangles, const BuildConfig& config, unsigned threads = 1);

/// Flattens a build tree into the hardware layout (node 0 an interior root, depth-first order,
/// triangles in leaf order) and fills the stats other than build_ms.
HwBvh flatten_bvh(const BuildTree& tree, const Scene& scene, const BuildConfig& config);

/// HwNodes of the flattened tree: its interior nodes, or 1 when the root is a leaf.
size_t flat_node_count(const BuildTree& tree);
/// flatten_bvh into arrays the caller provides (flat_node_count(tree) nodes and
/// tree.prim_ids.size() triangles, e.g. an image's regions); returns the stats.
BvhStats flatten_bvh_into(const BuildTree& tree, const Scene& scene, const BuildConfig& config, HwNode* nodes,
                          HwTriangle* triangles);

/// The hardware triangle record of scene primitive `prim` (vertices, ids, alpha and material
/// flags). Throws rtsim::Error if its material index does not fit the layout.
HwTriangle make_hw_triangle(const Scene& scene, uint32_t prim);

/// make_hw_triangle for many primitives of one scene: each material's flags are worked out once.
class HwTriangleWriter {
public:
    explicit HwTriangleWriter(const Scene& scene);
    HwTriangle operator()(uint32_t prim) const;
    /// out[i] = the record of prims[i], i < count.
    void write(const uint32_t* prims, size_t count, HwTriangle* out) const;

private:
    const Scene& m_scene;
    std::vector<uint32_t> m_flags;  ///< per material (at most the 65,536 the layout holds)
};

/// Levels of object-median splits needed below a node of `count` primitives before every leaf
/// holds at most max_leaf_size: ceil(log2(ceil(count / max_leaf_size))).
uint32_t median_levels_needed(uint32_t count, uint32_t max_leaf_size);

}  // namespace rtsim
