#pragma once
// Refitting a binary build tree to moved geometry (docs/accel.md, "Moving scenes"): the
// topology (children, leaves and the primitives each leaf holds) is kept and every box is
// recomputed bottom-up from the triangles' new positions, as a driver's BVH update does
// (DXR's PERFORM_UPDATE; Wald et al. 2007, "Ray tracing deformable scenes using dynamic
// bounding volume hierarchies"). A refitted tree stays valid for any motion (every box bounds
// its subtree) but its quality falls as triangles drift from the groups they were built in;
// sah_cost() below tells how far, so a per-frame policy can rebuild when it pays.
#include <vector>

#include "traces/bvh/build_tree.h"
#include "traces/bvh/config.h"
#include "traces/scene/scene.h"

namespace rtsim {

/// `topology` with every box recomputed over `triangles` (the same primitives, moved). Throws
/// rtsim::Error if the tree names a primitive `triangles` does not have or a vertex is not finite.
BuildTree refit_build_tree(const BuildTree& topology, const std::vector<Triangle>& triangles);

/// Interior nodes a refit updates (every node of the tree above its leaves, leaves included:
/// each box is one pass over its children or its triangles).
size_t refit_node_count(const BuildTree& tree);

/// SAH cost of a binary build tree (the formula the binned builder minimises: C_t per interior
/// node and C_i per triangle, each weighted by its box's area over the root's), so a refitted
/// tree and a rebuilt one of the same frame are compared on one scale.
double sah_cost(const BuildTree& tree, const BuildConfig& config);

}  // namespace rtsim
