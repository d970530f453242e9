#pragma once
// Spatial-split BVH (SBVH) builder: Stich, Friedrich & Dietrich 2009, "Spatial splits in bounding
// volume hierarchies" (HPG 2009). At each node the best binned object split (Wald 2007) competes
// with the best spatial split, which cuts space at a bin plane and puts a triangle that straddles
// it into both children, each with the box of its clipped part (sbvh_clip.h). Spatial splits are
// tried only where the object split's children overlap (alpha), reference duplication is bounded
// by a budget, and straddlers are kept whole where that is cheaper (unsplitting).
//
// The result is the binary BuildTree every BVH kind starts from, with one difference from the
// binned builder's: prim_ids may hold a primitive several times (each leaf reference becomes its
// own triangle record). Every primitive is referenced at least once, and the union of a
// primitive's reference boxes contains it, so hits are those of any other BVH over the scene.
#include <vector>

#include "traces/bvh/build_tree.h"
#include "traces/bvh/sbvh_config.h"

namespace rtsim {

/// Builds an SBVH over the triangles. config: SAH constants, object bins, leaf size and depth
/// bound (as the binned builder); sbvh: spatial-split parameters. Deterministic. Throws
/// rtsim::Error on a non-finite vertex or a config that cannot hold the tree.
BuildTree build_sbvh(const std::vector<Triangle>& triangles, const BuildConfig& config,
                     const SbvhConfig& sbvh = {}, SbvhStats* stats = nullptr);

}  // namespace rtsim
