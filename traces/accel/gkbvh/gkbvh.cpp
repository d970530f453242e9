// The GK-BVH's clipped variant and image (gkbvh.h).
#include "traces/accel/gkbvh/gkbvh.h"

#include "traces/accel/bvh2/bvh2.h"
#include "traces/bvh/sbvh_builder.h"
#include "traces/common/error.h"
#include "traces/scene/scene.h"

namespace rtsim {

// Popov et al.'s clipped variant is the spatial split of Stich et al. 2009 made at every node:
// the same chopped binning and conservative clipping (sbvh_clip.h), with no object split to
// compete, no overlap threshold and no unsplitting.
BuildTree build_gk_clipped(const std::vector<Triangle>& triangles, const BuildConfig& config, const GkConfig& gk,
                           GkStats* stats) {
    SbvhConfig s;
    s.alpha = 0.0f;
    s.spatial_bins = gk.spatial_bins;
    s.reference_budget = gk.reference_budget;
    s.unsplit = false;
    s.object_splits = false;
    SbvhStats st;
    BuildTree tree = build_sbvh(triangles, config, s, &st);
    if (stats) *stats = GkStats{st.references, st.spatial_splits, st.median_splits};
    return tree;
}

AccelImage gkbvh_image(const Scene& scene, const std::string& builder, const BuildConfig& config, const GkConfig& gk) {
    require(builder == "clipped" || builder == "boxes", "gkbvh: no builder '" + builder + "'");
    GkStats st;
    const BuildTree tree = builder == "clipped" ? build_gk_clipped(scene.triangles, config, gk, &st)
                                                : build_gk_boxes(scene.triangles, config, gk, &st);
    AccelImage image = bvh2_image(tree, scene, config, builder);
    image.kind = "gkbvh";
    image.stats["gkbvh"] = {{"variant", builder},
                            {"build", builder == "clipped" ? "binned" : "full sweep"},
                            {"references", st.references},
                            {"duplication", double(st.references) / double(scene.triangles.size())},
                            {"spatial_splits", st.spatial_splits},
                            {"median_splits", st.median_splits}};
    return image;
}

}  // namespace rtsim
