#pragma once
// Configuration of the spatial-split BVH builder (Stich, Friedrich & Dietrich 2009, "Spatial
// splits in bounding volume hierarchies", HPG 2009). The SAH constants, object-split bins, leaf
// size and depth bound are the binned builder's (BuildConfig, config.h); these fields are what
// spatial splits add. Every field: what it does and what it costs.
#include <cstdint>

namespace rtsim {

struct SbvhConfig {
    /// Overlap threshold alpha (section 4.5): a node tries spatial splits only when the children
    /// of its best object split overlap by more than alpha x the root's surface area (or when no
    /// object split exists). Smaller tries spatial splits in more nodes: lower SAH cost, longer
    /// builds, more references. 1e-5 is the paper's value; 1 or more disables spatial splits (the
    /// result is then a plain binned SAH tree, up to binning details).
    float alpha = 1e-5f;
    /// Spatial-split bins per axis (section 4.3). More bins find better planes; the cost is linear
    /// in the bins and in the bins each straddling reference spans (it is clipped into each).
    uint32_t spatial_bins = 32;
    /// Extra references the whole build may create, as a fraction of the triangle count (1: at
    /// most 2N references, 0: no spatial split can duplicate). Each node passes what it did not
    /// use to its children in proportion to their references, so no subtree starves the others.
    /// Every reference is a 48-byte triangle record in the image: the budget bounds the memory.
    float reference_budget = 1.0f;
    /// Reference unsplitting (section 4.4): after a spatial split is chosen, a straddling
    /// reference goes whole to one side when that is cheaper by the SAH than duplicating it.
    /// Costs one SAH evaluation per straddling reference; saves references and usually SAH cost.
    bool unsplit = true;
    /// Object splits compete with spatial ones (Stich et al.). False: every split cuts space, as
    /// in the GK-BVH with clipped triangles (Popov et al. 2009, traces/accel/gkbvh); object
    /// median splits remain the fallback where no spatial split makes progress or depth runs out.
    /// Not a command-line setting of the sbvh builder: the gkbvh structure sets it.
    bool object_splits = true;

    /// The settings as data (traces/accel/build_settings.h).
    template <class V>
    void visit(V& v) {
        v.field("alpha", alpha, "x root area", "Spatial splits are tried where the best object split's children overlap by more than alpha x the root's area", 0, 1e6);
        v.field("spatial_bins", spatial_bins, "bins", "Spatial-split bin planes per axis", 2, 1024);
        v.field("reference_budget", reference_budget, "x N", "Extra references the build may create, as a fraction of the triangles (48 bytes each)", 0, 16);
        v.flag("unsplit", unsplit, "Reference unsplitting: a straddler goes whole to one side when the SAH says that is cheaper");
    }
};

/// What a spatial-split build did (written to the manifest's accel stats).
struct SbvhStats {
    uint64_t references = 0;     ///< leaf references (triangle records in the image)
    uint64_t object_splits = 0;
    uint64_t spatial_splits = 0;
    uint64_t median_splits = 0;  ///< fallbacks near max_depth or where the SAH found nothing
    uint64_t unsplit = 0;        ///< straddling references kept whole by unsplitting
};

}  // namespace rtsim
