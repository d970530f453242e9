// The GK-BVH (both variants), the B-Kd tree and the full-sweep and equal-count tree builders
// beyond what the space-partitioning tests sweep (hits against brute force and bvh2, hard cases:
// test_space_partition.cpp): each builder's tree checked by the BVH invariants, each structure's
// own invariants, and the properties that tell the builds apart.
#include <gtest/gtest.h>

#include "space_partition_util.h"
#include "traces/accel/bih/bih.h"
#include "traces/accel/bkd/bkd.h"
#include "traces/accel/gkbvh/gkbvh.h"
#include "traces/bvh/builder.h"
#include "traces/bvh/sweep_builder.h"
#include "traces/scene/procedural.h"

namespace rtsim {
namespace {

using test::build_named;

double sah_of(const Accel& a) { return a.image().stats["sah_cost"].get<double>(); }

TEST(ObjectBuilders, TreesKeepTheBvhInvariants) {
    const BuildConfig c;
    for (uint64_t seed : {1, 2}) {
        const Scene scene = test::random_soup(seed, 1500);
        EXPECT_NO_THROW(check_bvh_invariants(flatten_bvh(build_sweep_sah(scene.triangles, c), scene, c), scene));
        EXPECT_NO_THROW(check_bvh_invariants(flatten_bvh(build_median(scene.triangles, c), scene, c), scene));
        EXPECT_NO_THROW(check_bvh_invariants(flatten_bvh(build_sweep_termination(scene.triangles, c), scene, c), scene));
    }
}

TEST(ObjectBuilders, LocalRayTerminationPricesOccludersIntoItsSplits) {
    // A wall of large triangles beside a cloud of small ones: rays entering both stop at the
    // wall, which the termination-aware cost prices, so its tree differs from the sweep's (the
    // hits are the same: test_space_partition.cpp's kinds include bvh2:lrt).
    std::vector<Vec3> soup;
    for (int i = 0; i < 8; ++i) {  // the wall at x = 0: 8 big quads' halves
        const float y = float(i) - 4.0f;
        soup.insert(soup.end(), {Vec3(0, y, -4), Vec3(0, y + 1, -4), Vec3(0, y, 4)});
    }
    Rng rng(3);
    for (int i = 0; i < 600; ++i) {  // the cloud behind it
        const Vec3 c = test::random_point(rng, Vec3(0.5f, -4.0f, -4.0f), Vec3(8.0f, 4.0f, 4.0f));
        soup.insert(soup.end(), {c, c + Vec3(0.05f, 0, 0), c + Vec3(0, 0.05f, 0)});
    }
    const Scene scene = test::make_scene(soup);
    const auto sweep = build_named(scene, "bvh2:sweep"), lrt = build_named(scene, "bvh2:lrt");
    EXPECT_NE(sah_of(*lrt), sah_of(*sweep));
    EXPECT_NO_THROW(check_bvh_invariants(flatten_bvh(build_sweep_termination(scene.triangles, BuildConfig{}), scene,
                                                     BuildConfig{}),
                                         scene));
    const BuildTree a = build_sweep_sah(scene.triangles, BuildConfig{});
    const BuildTree b = build_sweep_termination(scene.triangles, BuildConfig{});
    EXPECT_NE(a.prim_ids, b.prim_ids);
}

TEST(ObjectBuilders, SweepPricesAtLeastAsWellAsBinsAndMedianIsBalanced) {
    for (const char* name : {"teapot_stadium", "rotated_walls", "cornell"}) {
        const Scene& scene = test::procedural(name);
        const double binned = sah_of(*build_named(scene, "bvh2")), sweep = sah_of(*build_named(scene, "bvh2:sweep"));
        const auto median = build_named(scene, "bvh2:median");
        // The sweep prices every boundary the bins price and more; greedy, so "at least as well"
        // holds for the tree only up to a margin.
        EXPECT_LE(sweep, binned * 1.02) << name;
        EXPECT_GT(sah_of(*median), sweep) << name << ": the median ignores the cost model";
        const uint64_t n = scene.triangles.size();
        EXPECT_LE(median->image().stats["max_depth"].get<uint64_t>(), median_levels_needed(uint32_t(n), 4) + 1) << name;
    }
}

TEST(GkBvh, BothVariantsKeepTheInvariantsWithDuplicates) {
    const BuildConfig c;
    const GkConfig gk;
    for (uint64_t seed : {3, 4}) {
        const Scene scene = test::random_soup(seed, 1200);
        GkStats clipped, boxes;
        const BuildTree a = build_gk_clipped(scene.triangles, c, gk, &clipped);
        const BuildTree b = build_gk_boxes(scene.triangles, c, gk, &boxes);
        EXPECT_NO_THROW(check_bvh_invariants(flatten_bvh(a, scene, c), scene, true)) << seed;
        EXPECT_NO_THROW(check_bvh_invariants(flatten_bvh(b, scene, c), scene, true)) << seed;
        // Space subdivision duplicates straddlers, within the budget, and splits mostly by planes.
        for (const GkStats* s : {&clipped, &boxes}) {
            EXPECT_GT(s->references, scene.triangles.size()) << seed;
            EXPECT_LE(s->references, uint64_t((1.0 + gk.reference_budget) * scene.triangles.size())) << seed;
            EXPECT_GT(s->spatial_splits, 4 * s->median_splits) << seed;
        }
    }
}

TEST(GkBvh, BudgetBoundsDuplicationAndStatsReachTheImage) {
    const Scene scene = test::random_soup(5, 1000);
    const auto none = build_named(scene, "gkbvh:boxes", {{"reference_budget", 0.0}});
    EXPECT_EQ(none->image().stats["gkbvh"]["references"].get<uint64_t>(), scene.triangles.size());
    const auto some = build_named(scene, "gkbvh", {{"reference_budget", 0.25}});
    const nlohmann::json& s = some->image().stats["gkbvh"];
    EXPECT_EQ(s["variant"], "clipped");
    EXPECT_EQ(s["build"], "binned");
    EXPECT_GT(s["duplication"].get<double>(), 1.0);
    EXPECT_LE(s["duplication"].get<double>(), 1.25 + 1e-9);
    EXPECT_EQ(some->kind(), "gkbvh");
    EXPECT_EQ(build_named(scene, "gkbvh:boxes")->image().stats["gkbvh"]["build"], "full sweep");
}

TEST(GkBvh, ClippedTrianglesGiveTighterBoxesThanClippedBoxes) {
    // Long thin diagonal triangles: a box cut at a plane keeps the whole diagonal's extent, the
    // clipped triangle only its part.
    const Scene& scene = test::procedural("rotated_walls");
    EXPECT_LT(sah_of(*build_named(scene, "gkbvh")), sah_of(*build_named(scene, "gkbvh:boxes"))) << "rotated_walls";
}

TEST(Bkd, InvariantsAndCellsNoLargerThanTheBihs) {
    for (uint64_t seed : {6, 7}) {
        const Scene scene = test::random_soup(seed, 1500);
        for (const char* name : {"bkd", "bkd:sweep", "bkd:median", "bkd:lbvh"}) {
            const auto a = build_named(scene, name);
            EXPECT_NO_THROW(check_bkd_invariants(static_cast<const BkdAccel&>(*a).view(), scene)) << name;
        }
        // Four planes bound a child at least as tightly as the BIH's two, on the same tree.
        EXPECT_LT(sah_of(*build_named(scene, "bkd")), sah_of(*build_named(scene, "bih"))) << seed;
    }
}

TEST(Bkd, PlaneTestsAreFourPerInteriorStep) {
    const Scene& scene = test::procedural("cornell");
    const auto a = build_named(scene, "bkd");
    const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), 8, 200);
    for (const Ray& r : rays) {
        WorkCounts w;
        a->trace(r, TraversalMode::closest_hit, &w);
        EXPECT_EQ(w.plane_tests % 4, 0u);
    }
}

}  // namespace
}  // namespace rtsim
