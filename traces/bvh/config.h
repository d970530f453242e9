#pragma once
// Configuration of the binned SAH builder (Wald 2007, "On fast construction of SAH-based
// bounding volume hierarchies"). Every field: what it does and what it costs.
#include <cstdint>

namespace rtsim {

struct BuildConfig {
    /// SAH bins per axis. More bins find better splits at a linear build-time cost.
    uint32_t bins = 16;
    /// Cost of visiting one interior node, relative to intersection_cost (SAH constant C_t).
    float traversal_cost = 1.0f;
    /// Cost of one ray/triangle test (SAH constant C_i).
    float intersection_cost = 1.0f;
    /// Largest leaf. Leaves this size or smaller are made when the SAH says splitting does not
    /// pay; bigger ranges are always split (median split if the SAH finds nothing).
    uint32_t max_leaf_size = 4;
    /// Deepest allowed tree; beyond depth max_depth - 8 the builder splits at the object median
    /// so the traversal stack (kTraversalStackSize entries) can never overflow.
    uint32_t max_depth = 64;
};

}  // namespace rtsim
