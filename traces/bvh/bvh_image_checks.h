#pragma once
// Structural validation of a BVH memory image read from a trace (DESIGN rule 11).
//
// Contract: a trace's CRCs prove the bytes are the ones written, not that they make a tree. A
// node image that passes validate_bvh_image() can be traversed by the reference stepper and the
// model without reading outside `nodes` or `triangles`, without looping and without
// overflowing the traversal stack (kTraversalStackSize entries). Checked in O(nodes + triangles):
//   - at least one node and one triangle;
//   - node 0 is the root; every interior child index is in [1, nodes) and every node is reached
//     exactly once from the root (so the image is a tree: no cycle, no shared subtree, no
//     unreachable node);
//   - every leaf lies inside the triangle section, has 1..kMaxLeafTriangles triangles, and every
//     triangle belongs to exactly one leaf (so every triangle is reachable);
//   - an empty child slot (kEmptyChild) only as child 1 of a root whose child 0 is a leaf, with
//     a box no ray can enter (lo > hi on every axis), as the builder writes it;
//   - no interior node deeper than the traversal stack allows (root at depth 0; a node at depth
//     d can hold at most d + 1 entries on the stack);
//   - no NaN in a box that can be entered, each triangle's `prim` below the triangle count and
//     used once (the hit checker and heatmaps index by it).
// Throws rtsim::Error "<source>: BVH node N child C: <what>" (or "... triangle T ...").
#include <cstdint>
#include <string>
#include <vector>

#include "traces/bvh/hw_layout.h"

namespace rtsim {

/// Largest leaf accepted in a trace. The builder's leaves hold BuildConfig::max_leaf_size
/// triangles (default 4); this bound only keeps a corrupt count from meaning a huge fetch.
constexpr uint32_t kMaxLeafTriangles = 1u << 16;

/// Validates a node and triangle image (see the contract above); `source` names the file.
void validate_bvh_image(const std::vector<HwNode>& nodes, const std::vector<HwTriangle>& triangles,
                        const std::string& source);

}  // namespace rtsim
