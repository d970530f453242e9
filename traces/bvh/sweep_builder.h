#pragma once
// Object-partitioning builders beside the binned SAH (builder.h), as the sources compare them:
//
//   sweep   the full sweeping-plane SAH (MacDonald & Booth 1990; Wald 2007, section 2): every
//           object boundary on every axis is priced, from the references sorted by centroid, so
//           the split is the SAH's best object partition exactly (no bins). O(N log^2 N).
//   lrt     the full sweep with local ray termination in its cost (after Moulin & Dutre 2018's
//           use of it to build BSPs, BIHs and BVHs): a split's cost is lowered by the tests a ray
//           saves when it stops in the child it visits first, estimated from the children's
//           triangle area over their box area; the rest as `sweep`.
//   median  the equal-count split (Kay & Kajiya 1986's median cut): the centroid median on the
//           widest centroid axis, no cost model; the tree is balanced and leaves are as full as
//           max_leaf_size allows.
//
// Both produce the BuildTree every BVH kind (and BIH, B-Kd) starts from, with prim_ids a
// permutation of the primitives, deterministic for a scene and config.
#include <vector>

#include "traces/bvh/build_tree.h"

namespace rtsim {

/// The full-sweep SAH build. Same leaf rule and depth guard as the binned builder: a node of at
/// most max_leaf_size is a leaf when splitting does not pay; beyond max_depth - 8 median splits.
BuildTree build_sweep_sah(const std::vector<Triangle>& triangles, const BuildConfig& config);
/// The full sweep with local ray termination in the split cost (the header's `lrt`).
BuildTree build_sweep_termination(const std::vector<Triangle>& triangles, const BuildConfig& config);
/// The equal-count build: every node of more than max_leaf_size is halved at its centroid median.
BuildTree build_median(const std::vector<Triangle>& triangles, const BuildConfig& config);

}  // namespace rtsim
