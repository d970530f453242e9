#pragma once
// The GK-BVH behind the acceleration-structure seam (Popov, Georgiev, Dimov & Slusallek 2009,
// "Object partitioning considered harmful: space subdivision for BVHs", HPG; docs/accel.md,
// "gkbvh"): a binary BVH built by space subdivision alone, as a kd-tree is, with the nodes'
// boxes of a BVH. Every split cuts the node at a plane; a triangle straddling it is referenced on
// both sides (reference duplication), and each child's box bounds the parts of its references on
// its side, so children never overlap. The image is a binary BVH's (bvh2.h, docs/bvh_layout.md:
// 64-byte nodes, one 48-byte triangle record per reference), traced by the binary BVH's steppers.
//
// Two variants, as builders, since each admits a different build:
//
//   clipped  (default) a straddling triangle is clipped against the plane and each side gets the
//            box of its part (sbvh_clip.h): the tightest boxes. Where a piece lies depends on
//            the triangle's shape, not its box, so no sorted order prices every plane: the build
//            is binned (spatial_bins planes per axis, each straddler chopped into the bins).
//   boxes    a straddling reference's box is cut at the plane instead: looser boxes, but a side's
//            box is then a union of whole boxes cut at the plane, so a sweep over the references
//            sorted by their box ends prices every candidate plane exactly (a full sweep, as a
//            kd-tree's SAH build: Wald & Havran 2006), in O(N log N) per level.
//
// Duplicated references repeat along a ray, as in a kd-tree; the retest of a triangle never
// changes the hit (closest hits are kept by (t, prim): traces/isect/leaf_kernel.h).
#include <string>
#include <vector>

#include "traces/accel/accel.h"
#include "traces/bvh/build_tree.h"

namespace rtsim {

struct Scene;

/// The GK-BVH builders' settings beyond the binned builder's (SAH costs, leaf size, depth).
struct GkConfig {
    /// Candidate planes per axis of the clipped variant's binning (the sweep prices every plane).
    /// More bins find better planes; the cost is linear in the bins each straddler spans.
    uint32_t spatial_bins = 32;
    /// Extra references the build may create, as a fraction of the triangles (each a 48-byte
    /// triangle record). The SAH alone bounds duplication in the paper; this bounds the memory.
    float reference_budget = 4.0f;

    /// The settings as data (traces/accel/build_settings.h).
    template <class V>
    void visit(V& v, bool binned) {
        if (binned) v.field("spatial_bins", spatial_bins, "bins", "Candidate planes per axis (clipped variant: binned)", 2, 1024);
        v.field("reference_budget", reference_budget, "x N", "Extra references the build may create, as a fraction of the triangles (48 bytes each)", 0, 16);
    }
};

/// What a GK-BVH build did (written to the image's stats).
struct GkStats {
    uint64_t references = 0;     ///< leaf references (triangle records in the image)
    uint64_t spatial_splits = 0;
    uint64_t median_splits = 0;  ///< object-median fallbacks: no plane made progress, or depth ran out
};

/// The boxes variant's full-sweep build over the triangles. Deterministic.
BuildTree build_gk_boxes(const std::vector<Triangle>& triangles, const BuildConfig& config, const GkConfig& gk,
                         GkStats* stats);
/// The clipped variant's binned build (the spatial-split builder with object splits off).
BuildTree build_gk_clipped(const std::vector<Triangle>& triangles, const BuildConfig& config, const GkConfig& gk,
                           GkStats* stats);
/// The image of a built GK-BVH: a binary BVH's regions, kind "gkbvh", with the build's stats.
AccelImage gkbvh_image(const Scene& scene, const std::string& builder, const BuildConfig& config, const GkConfig& gk);

}  // namespace rtsim
