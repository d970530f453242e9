#pragma once
// Locality partitions: which "treelet" (or block of cells) each step of a structure belongs to,
// so ray buffers and reordering work for every structure (docs/treelets.md). A structure maps
// each step to a locality key (StepPlan::locality: its node or cell index); a partition maps
// keys to groups that each fit a byte budget.
//
// Tree structures share one partitioner: treelets are grown greedily (Aila & Karras 2010,
// "Architecture considerations for tracing incoherent rays", section 4): a treelet starts at a
// root and repeatedly adds, among the nodes adjacent to it, the one a ray is most likely to reach
// (largest surface area, the SAH probability); a candidate that does not fit starts a treelet of
// its own, and a subtree that fits what is left is taken whole. Left-over subtrees smaller than
// the budget are packed together (first fit) rather than each forming a tiny treelet. Every
// node lands in exactly one treelet. Deterministic: ties go to the smaller node index.
#include <cstdint>
#include <vector>

namespace rtsim {

struct TreeletInfo {
    uint32_t root = 0;     ///< locality key (node) of the treelet's root
    uint32_t nodes = 0;    ///< keys (nodes or cells) in the treelet
    uint64_t bytes = 0;    ///< bytes of its nodes plus the primitives only they reference
    uint32_t depth = 0;    ///< treelets crossed from the root's treelet (which has depth 0)
};

struct LocalityPartition {
    uint64_t budget_bytes = 0;
    std::vector<uint32_t> group_of;      ///< treelet of every locality key
    std::vector<TreeletInfo> treelets;
    uint32_t root_group = 0;             ///< where rays start when their first step has no key
};

/// A tree as the partitioner sees it. Node 0 is the root; every child has a larger index than
/// its parent (depth-first layouts satisfy this).
struct LocalityTree {
    std::vector<uint64_t> bytes;         ///< bytes node i brings: itself plus its leaf primitives
    std::vector<float> area;             ///< its box's surface area (root: +inf)
    std::vector<uint32_t> child_begin;   ///< children of i: children[child_begin[i], child_begin[i+1])
    std::vector<uint32_t> children;

    uint32_t size() const { return uint32_t(bytes.size()); }
    /// Appends a node; its children are added with add_child until the next add_node.
    void add_node(uint64_t node_bytes, float node_area);
    void add_child(uint32_t child);
    /// Closes the child lists (call once after the last node).
    void finish();
};

/// Partitions a tree under a byte budget per treelet. A single node whose bytes exceed the
/// budget forms a treelet by itself (the only way a treelet can exceed the budget).
LocalityPartition partition_tree(const LocalityTree& tree, uint64_t budget_bytes);

/// Throws rtsim::Error naming the first broken invariant: a node in no treelet or an invalid one,
/// a treelet over budget with more than one node, a packed subtree split across treelets, byte
/// or node counts that do not add up.
void check_tree_partition(const LocalityTree& tree, const LocalityPartition& partition);

}  // namespace rtsim
