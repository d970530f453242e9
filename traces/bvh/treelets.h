#pragma once
// Treelet partitioning of the hardware BVH (Aila & Karras 2010, "Architecture considerations for
// tracing incoherent rays", section 4): the tree is cut into treelets that each fit a byte budget,
// so a treelet can stay on chip while a queue of rays traverses it. Greedy growth: a treelet starts
// at a root and repeatedly adds, among the nodes adjacent to it, the one a ray is most likely to
// reach (largest surface area, the SAH probability); a candidate that does not fit starts a treelet
// of its own, and a subtree that fits what is left is taken whole. Left-over subtrees smaller than
// the budget are packed together (first fit) rather than each forming a tiny treelet. Every
// interior node lands in exactly one treelet; a leaf's triangles belong to the treelet of the
// node that references them. Deterministic: ties go to the smaller node index.
#include <cstdint>
#include <vector>

#include "traces/bvh/hw_layout.h"

namespace rtsim {

struct TreeletInfo {
    uint32_t root = 0;     ///< node index of the treelet's root
    uint32_t nodes = 0;    ///< interior nodes in the treelet
    uint64_t bytes = 0;    ///< node bytes plus the bytes of the leaf triangles they reference
    uint32_t depth = 0;    ///< treelets crossed from the BVH root's treelet (which has depth 0)
};

struct TreeletPartition {
    uint32_t budget_bytes = 0;
    std::vector<uint32_t> node_treelet;  ///< treelet of every node
    std::vector<TreeletInfo> treelets;   ///< treelet 0 holds the root node
};

/// Bytes a node brings into its treelet: itself plus the triangles of its leaf children.
uint64_t node_footprint(const HwNode& node);

/// Partitions the BVH under a byte budget per treelet. A single node whose footprint exceeds the
/// budget forms a treelet by itself (the only way a treelet can exceed the budget).
TreeletPartition partition_treelets(const std::vector<HwNode>& nodes, uint32_t budget_bytes);

/// Throws rtsim::Error naming the first broken invariant: a node in no treelet or an invalid one,
/// a treelet over budget with more than one node, a packed subtree split across treelets, byte
/// or node counts that do not add up.
void check_treelet_partition(const std::vector<HwNode>& nodes, const TreeletPartition& partition);

}  // namespace rtsim
