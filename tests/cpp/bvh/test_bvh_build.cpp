// Binned SAH builder and flattening: invariants on many scene shapes, the hardware layout's
// corner cases, determinism, and the limits the config promises.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "bvh_test_scenes.h"
#include "traces/bvh/build_tree.h"
#include "traces/bvh/builder.h"
#include "traces/common/error.h"

namespace rtsim {
namespace {

using test::make_scene;
using test::random_triangles;

/// Walks the flattened tree and returns the sizes of all leaves and the deepest leaf depth.
struct LeafWalk {
    std::vector<uint32_t> sizes;
    uint32_t max_depth = 0;
};
LeafWalk walk_leaves(const HwBvh& bvh) {
    LeafWalk walk;
    std::vector<std::pair<uint32_t, uint32_t>> stack{{0u, 0u}};
    while (!stack.empty()) {
        auto [node, depth] = stack.back();
        stack.pop_back();
        for (int s = 0; s < 2; ++s) {
            uint32_t count = bvh.nodes[node].child_count[s];
            if (count == 0) stack.push_back({bvh.nodes[node].child_ref[s], depth + 1});
            if (count == 0 || count == kEmptyChild) continue;
            walk.sizes.push_back(count);
            walk.max_depth = std::max(walk.max_depth, depth + 1);
        }
    }
    return walk;
}

class RandomSceneSizes : public ::testing::TestWithParam<size_t> {};

TEST_P(RandomSceneSizes, InvariantsAndStatsHold) {
    Scene scene = make_scene(random_triangles(GetParam(), 42 + GetParam()));
    HwBvh bvh = build_bvh(scene);
    EXPECT_NO_THROW(check_bvh_invariants(bvh, scene));
    LeafWalk walk = walk_leaves(bvh);
    EXPECT_EQ(bvh.stats.nodes, bvh.nodes.size());
    EXPECT_EQ(bvh.stats.leaves, walk.sizes.size());
    EXPECT_EQ(bvh.stats.max_depth, walk.max_depth);
    EXPECT_EQ(bvh.stats.max_leaf_size, *std::max_element(walk.sizes.begin(), walk.sizes.end()));
    EXPECT_LE(bvh.stats.max_leaf_size, 4u);
    EXPECT_DOUBLE_EQ(bvh.stats.avg_leaf_size, double(GetParam()) / walk.sizes.size());
    EXPECT_DOUBLE_EQ(bvh.stats.sah_cost, sah_cost(bvh, BuildConfig{}));
    EXPECT_GE(bvh.stats.build_ms, 0.0);
    EXPECT_EQ(bvh.bounds.lo, scene.bounds.lo);
    EXPECT_EQ(bvh.bounds.hi, scene.bounds.hi);
    if (GetParam() > 1) {
        EXPECT_GT(bvh.stats.sah_cost, 1.0);
    }
}

INSTANTIATE_TEST_SUITE_P(Sizes, RandomSceneSizes,
                         ::testing::Values(size_t(1), size_t(2), size_t(3), size_t(5),
                                           size_t(1000), size_t(100000)));

TEST(BvhBuild, OneLeafSceneGetsInteriorRootWithEmptySecondChild) {
    Scene scene = make_scene(random_triangles(1, 7));
    HwBvh bvh = build_bvh(scene);
    ASSERT_EQ(bvh.nodes.size(), 1u);
    const HwNode& root = bvh.nodes[0];
    EXPECT_EQ(root.child_ref[0], 0u);
    EXPECT_EQ(root.child_count[0], 1u);
    EXPECT_EQ(root.child_count[1], kEmptyChild);
    for (int a = 0; a < 3; ++a) {
        EXPECT_EQ(root.lo(1, a), std::numeric_limits<float>::infinity());
        EXPECT_EQ(root.hi(1, a), -std::numeric_limits<float>::infinity());
    }
    EXPECT_EQ(bvh.stats.leaves, 1u);
    EXPECT_EQ(bvh.stats.max_depth, 1u);
}

TEST(BvhBuild, LeftChildFollowsItsParent) {
    Scene scene = make_scene(random_triangles(5000, 3));
    HwBvh bvh = build_bvh(scene);
    for (size_t i = 0; i < bvh.nodes.size(); ++i)
        if (bvh.nodes[i].child_count[0] == 0) {
            EXPECT_EQ(bvh.nodes[i].child_ref[0], i + 1) << i;
        }
}

TEST(BvhBuild, IdenticalCentroidsAreSplitByMedian) {
    // Symmetric triangles about one point: every box centre (the binning centroid) coincides.
    Rng rng(5);
    std::vector<Triangle> tris;
    Vec3 c(1.0f, 2.0f, 3.0f);
    for (int i = 0; i < 1000; ++i) {
        Vec3 d(rng.next(), rng.next(), rng.next());
        tris.push_back(Triangle{c + d, c - d, c});
    }
    for (int i = 0; i < 100; ++i) tris.push_back(tris[0]);  // exact duplicates too
    Scene scene = make_scene(tris);
    HwBvh bvh = build_bvh(scene);
    EXPECT_NO_THROW(check_bvh_invariants(bvh, scene));
    EXPECT_LE(bvh.stats.max_leaf_size, 4u);
    EXPECT_LE(bvh.stats.max_depth, 64u);
}

TEST(BvhBuild, DegenerateTrianglesAreReferencedOnce) {
    std::vector<Triangle> tris = random_triangles(200, 9);
    Rng rng(11);
    for (int i = 0; i < 300; ++i) {
        Vec3 p(rng.next(), rng.next(), rng.next());
        Vec3 d(rng.next(), rng.next(), rng.next());
        if (i % 3 == 0) tris.push_back(Triangle{p, p, p});                 // a point
        if (i % 3 == 1) tris.push_back(Triangle{p, p + d, p + 2.0f * d});  // collinear
        if (i % 3 == 2) tris.push_back(Triangle{Vec3(0.5f), Vec3(0.5f), Vec3(0.5f)});  // one spot
    }
    Scene scene = make_scene(tris);
    HwBvh bvh = build_bvh(scene);
    EXPECT_NO_THROW(check_bvh_invariants(bvh, scene));
    EXPECT_LE(bvh.stats.max_leaf_size, 4u);
}

TEST(BvhBuild, AllTrianglesOnOnePointStillBuild) {
    std::vector<Triangle> tris(50, Triangle{Vec3(1.0f), Vec3(1.0f), Vec3(1.0f)});
    Scene scene = make_scene(tris);
    HwBvh bvh = build_bvh(scene);
    EXPECT_NO_THROW(check_bvh_invariants(bvh, scene));
    EXPECT_LE(bvh.stats.max_leaf_size, 4u);
    EXPECT_TRUE(std::isfinite(bvh.stats.sah_cost));
}

TEST(BvhBuild, HugeAndTinyCoordinates) {
    for (float scale : {1e6f, 1e-6f}) {
        std::vector<Triangle> tris = random_triangles(5000, 13, scale, scale * 0.01f);
        // Offset far from the origin too, where float spacing is coarse.
        for (Triangle& t : tris)
            for (Vec3* v : {&t.v0, &t.v1, &t.v2}) *v += Vec3(scale * 1000.0f);
        Scene scene = make_scene(tris);
        HwBvh bvh = build_bvh(scene);
        EXPECT_NO_THROW(check_bvh_invariants(bvh, scene)) << scale;
        EXPECT_LE(bvh.stats.max_leaf_size, 4u) << scale;
        EXPECT_TRUE(std::isfinite(bvh.stats.sah_cost)) << scale;
    }
}

TEST(BvhBuild, Deterministic) {
    Scene scene = make_scene(test::clustered_triangles(20000, 6, 17));
    HwBvh a = build_bvh(scene);
    HwBvh b = build_bvh(scene);
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    ASSERT_EQ(a.triangles.size(), b.triangles.size());
    EXPECT_EQ(std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(HwNode)), 0);
    EXPECT_EQ(std::memcmp(a.triangles.data(), b.triangles.data(),
                          a.triangles.size() * sizeof(HwTriangle)),
              0);
}

TEST(BvhBuild, MaxLeafSizeRespected) {
    Scene scene = make_scene(random_triangles(3000, 19));
    for (uint32_t leaf : {1u, 2u, 7u, 16u}) {
        BuildConfig config;
        config.max_leaf_size = leaf;
        config.traversal_cost = 8.0f;  // make big leaves attractive to the SAH
        HwBvh bvh = build_bvh(scene, config);
        EXPECT_NO_THROW(check_bvh_invariants(bvh, scene));
        for (uint32_t size : walk_leaves(bvh).sizes) ASSERT_LE(size, leaf);
        EXPECT_LE(bvh.stats.max_leaf_size, leaf);
        if (leaf == 1) {
            EXPECT_EQ(bvh.stats.leaves, 3000u);
        }
    }
}

TEST(BvhBuild, DepthBoundedOnExponentialSpacing) {
    // Triangles at x = 1.1^i: binned SAH keeps peeling the far end off, a chain of depth ~N.
    std::vector<Triangle> tris;
    for (int i = 0; i < 900; ++i) {
        float x = std::pow(1.1f, float(i));
        float s = x * 0.01f;
        tris.push_back(Triangle{Vec3(x, 0, 0), Vec3(x + s, s, 0), Vec3(x, 0, s)});
    }
    Scene scene = make_scene(tris);
    for (uint32_t max_depth : {64u, 24u, 12u, 8u}) {
        BuildConfig config;
        config.max_depth = max_depth;
        HwBvh bvh = build_bvh(scene, config);
        EXPECT_NO_THROW(check_bvh_invariants(bvh, scene));
        EXPECT_LE(bvh.stats.max_depth, max_depth);
        EXPECT_EQ(walk_leaves(bvh).max_depth, bvh.stats.max_depth);
        EXPECT_LE(bvh.stats.max_leaf_size, 4u);
    }
    // The unconstrained tree really is deep: the guard above was exercised.
    BuildConfig deep;
    EXPECT_GT(build_bvh(scene, deep).stats.max_depth, 24u);
}

TEST(BvhBuild, MedianLevelsNeeded) {
    EXPECT_EQ(median_levels_needed(1, 4), 0u);
    EXPECT_EQ(median_levels_needed(4, 4), 0u);
    EXPECT_EQ(median_levels_needed(5, 4), 1u);
    EXPECT_EQ(median_levels_needed(8, 4), 1u);
    EXPECT_EQ(median_levels_needed(9, 4), 2u);
    EXPECT_EQ(median_levels_needed(262144, 4), 16u);
    EXPECT_EQ(median_levels_needed(262145, 4), 17u);
    EXPECT_EQ(median_levels_needed(0x7FFFFFFFu, 1), 31u);
}

TEST(BvhBuild, TriangleFlagsFromMaterial) {
    Material mask;
    mask.alpha_mode = AlphaMode::mask;
    mask.alpha_coverage = 0.5f;
    Scene scene = make_scene(random_triangles(10, 23), mask);
    scene.materials.push_back(Material{});
    scene.tri_material[3] = 1;  // an opaque second material
    HwBvh bvh = build_bvh(scene);
    for (const HwTriangle& t : bvh.triangles) {
        if (t.prim == 3) {
            EXPECT_EQ(t.flags, (255u << kTriCoverageShift) | (1u << kTriMaterialShift));
        } else {
            EXPECT_EQ(t.flags, kTriAnyHit | (128u << kTriCoverageShift));
        }
        EXPECT_EQ(t.inst, 0u);
    }
}

TEST(BvhBuild, SahCostOfTwoSeparatedTriangles) {
    // Two unit right triangles 10 apart on x: root box 11x1x0, leaves 1x1x0 each.
    std::vector<Triangle> tris = {
        Triangle{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)},
        Triangle{Vec3(10, 0, 0), Vec3(11, 0, 0), Vec3(10, 1, 0)},
    };
    Scene scene = make_scene(tris);
    BuildConfig config;
    config.max_leaf_size = 1;
    HwBvh bvh = build_bvh(scene, config);
    ASSERT_EQ(bvh.nodes.size(), 1u);
    // root: C_t x 1; leaves: C_i x 1 x (1 / 11) each.
    EXPECT_NEAR(bvh.stats.sah_cost, 1.0 + 2.0 / 11.0, 1e-9);
    config.traversal_cost = 2.0f;
    config.intersection_cost = 3.0f;
    EXPECT_NEAR(sah_cost(bvh, config), 2.0 + 6.0 / 11.0, 1e-9);
}

TEST(BvhBuild, RefusesBadInput) {
    Scene empty;
    empty.materials.push_back(Material{});
    empty.flatten();
    try {
        build_bvh(empty);
        FAIL() << "empty scene accepted";
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(), "scene has no triangles");
    }
    std::vector<Triangle> tris = random_triangles(1000, 29);
    tris[17].v1.y = std::nanf("");
    EXPECT_THROW(build_bvh(make_scene(tris)), Error);

    Scene scene = make_scene(random_triangles(1000, 31));
    BuildConfig bad_bins;
    bad_bins.bins = 1;
    EXPECT_THROW(build_bvh(scene, bad_bins), Error);
    BuildConfig too_shallow;
    too_shallow.max_depth = 4;  // 1000 triangles need 8 median levels at 4 per leaf
    EXPECT_THROW(build_bvh(scene, too_shallow), Error);
    BuildConfig too_deep;
    too_deep.max_depth = 65;  // beyond the traversal stack
    EXPECT_THROW(build_bvh(scene, too_deep), Error);
}

}  // namespace
}  // namespace rtsim
