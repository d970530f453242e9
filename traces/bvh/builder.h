#pragma once
// BVH construction for a scene: binned SAH build-time tree, then flattened into the hardware
// layout. Contract: deterministic for the same scene and config; every triangle referenced
// exactly once; child boxes inside their parents.
#include "traces/bvh/config.h"
#include "traces/bvh/hw_layout.h"
#include "traces/scene/scene.h"

namespace rtsim {

/// Builds the hardware BVH over scene.triangles (flattened world space).
HwBvh build_bvh(const Scene& scene, const BuildConfig& config = {});

/// Throws rtsim::Error naming the first broken invariant (child box outside its parent,
/// triangle referenced zero or twice, triangle outside its leaf box, bad child reference).
/// With spatial_splits (SBVH) a primitive may be stored in several triangle records (each in
/// one leaf), a record need only overlap its leaf box, and the parts of a primitive inside its
/// records' leaf boxes must cover its whole area; every primitive is still stored at least once.
void check_bvh_invariants(const HwBvh& bvh, const Scene& scene, bool spatial_splits = false);

/// SAH cost of a flattened tree (same formula the builder minimises, relative to root area).
double sah_cost(const HwBvh& bvh, const BuildConfig& config);
/// The same over `count` nodes of a flattened tree (node 0 the root).
double sah_cost(const HwNode* nodes, size_t count, const BuildConfig& config);

}  // namespace rtsim
