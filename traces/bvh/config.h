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

    /// The settings as data (traces/accel/build_settings.h): one line per field. `with_bins`:
    /// false for builders that take no SAH bins (LBVH; the costs still price the tree).
    template <class V>
    void visit(V& v, bool with_bins = true) {
        if (with_bins) v.field("bins", bins, "bins", "SAH bins per axis: more find better splits, linear build cost", 2, 1024);
        v.field("traversal_cost", traversal_cost, "C_t", "SAH cost of visiting an interior node, relative to a triangle test", 0.001, 1000);
        v.field("intersection_cost", intersection_cost, "C_i", "SAH cost of one ray/triangle test", 0.001, 1000);
        v.field("max_leaf_size", max_leaf_size, "triangles", "Largest leaf; larger ranges are always split", 1, 64);
        v.field("max_depth", max_depth, "levels", "Deepest tree (median splits below max_depth - 8; the traversal stack holds 64)", 16, 64);
    }
};

}  // namespace rtsim
