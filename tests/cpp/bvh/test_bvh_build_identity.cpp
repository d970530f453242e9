// The binned SAH builder's speed work changed no tree: the build trees of scenes that exercise
// its every path (large and small nodes, ties on signed zeros, duplicates and degenerate
// triangles, bin counts below and above 64, leaf sizes, the depth guard) hash to the values the
// original single-pass algorithm (every bin swept, the bins refilled per node) produced, on one
// thread and on several. And the shortcuts around flattening give the images the long way gives.
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "bvh_test_scenes.h"
#include "tests/cpp/error_of.h"
#include "traces/accel/bvh2/bvh2.h"
#include "traces/bvh/build_tree.h"
#include "traces/bvh/builder.h"

namespace rtsim {
namespace {

uint64_t fnv1a(const void* p, size_t n, uint64_t h) {
    const auto* b = static_cast<const uint8_t*>(p);
    for (size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
    return h;
}

/// Nodes (boxes, references, counts; in the builder's numbering) and the primitive order.
uint64_t tree_hash(const BuildTree& t) {
    const uint64_t h = fnv1a(t.nodes.data(), t.nodes.size() * sizeof(BuildNode), 1469598103934665603ull);
    return fnv1a(t.prim_ids.data(), t.prim_ids.size() * sizeof(uint32_t), h);
}

/// Triangles on a lattice around the origin with signed zeros, duplicates, degenerate ones and
/// coincident centroids: the ties the builder must break as the reference does.
std::vector<Triangle> tie_triangles(uint64_t seed) {
    Rng rng(seed);
    std::vector<Triangle> out;
    auto coord = [&] {
        const int k = int(rng.next() * 9.0f) - 4;
        return k == 0 ? (rng.next() < 0.5f ? -0.0f : 0.0f) : float(k) * 0.25f;
    };
    for (int i = 0; i < 6000; ++i) {
        const Vec3 a(coord(), coord(), coord()), b(coord(), coord(), coord()), c(coord(), coord(), coord());
        out.push_back(Triangle{a, b, c});
        if (rng.next() < 0.1f) out.push_back(out.back());          // exact duplicate
        if (rng.next() < 0.05f) out.push_back(Triangle{a, a, b});  // degenerate
    }
    return out;
}

struct Case {
    const char* name;
    std::vector<Triangle> triangles;
    BuildConfig config;
    uint64_t hash;  ///< of the tree the original algorithm builds (git aad1a2f)
};

std::vector<Case> cases() {
    BuildConfig seven, many, leaf1, leaf8, shallow;
    seven.bins = 7;
    many.bins = 100;
    leaf1.max_leaf_size = 1;
    leaf8.max_leaf_size = 8;
    leaf8.traversal_cost = 2.0f;
    shallow.max_depth = 20;
    return {
        {"random 20000", test::random_triangles(20000, 1), BuildConfig{}, 0x63f546080ee66bd2ull},
        {"clustered 30000", test::clustered_triangles(30000, 7, 2), BuildConfig{}, 0xafb1049d1ba5c495ull},
        {"ties", tie_triangles(3), BuildConfig{}, 0x7ec829b2e9bd4e03ull},
        {"random, 7 bins", test::random_triangles(8000, 4), seven, 0xe0ee1df51eb49d24ull},
        {"clustered, 100 bins", test::clustered_triangles(8000, 5, 5), many, 0xf2d7e274d33e11e9ull},
        {"ties, leaves of 1", tie_triangles(6), leaf1, 0xfe31fa8ffa5e3879ull},
        {"random, leaves of 8", test::random_triangles(8000, 7, 1.0f, 0.2f), leaf8, 0x4e7992f766a9260full},
        {"clustered, depth 20", test::clustered_triangles(20000, 12, 8), shallow, 0x1e25ab8e9c9388a9ull},
    };
}

TEST(BinnedSahIdentity, TreesHashToTheOriginalAlgorithmsOnAnyThreadCount) {
    for (const Case& c : cases()) {
        const BuildTree one = build_binned_sah(c.triangles, c.config);
        EXPECT_EQ(tree_hash(one), c.hash) << c.name;
        for (unsigned threads : {2u, 3u, 8u}) {
            const BuildTree many = build_binned_sah(c.triangles, c.config, threads);
            ASSERT_EQ(many.nodes.size(), one.nodes.size()) << c.name << ", " << threads << " threads";
            EXPECT_EQ(std::memcmp(many.nodes.data(), one.nodes.data(), one.nodes.size() * sizeof(BuildNode)), 0)
                << c.name << ", " << threads << " threads";
            EXPECT_EQ(many.prim_ids, one.prim_ids) << c.name << ", " << threads << " threads";
        }
    }
}

TEST(BinnedSahIdentity, ThreadsSurviveTinyAndSingleTriangleScenes) {
    for (size_t n : {size_t(1), size_t(2), size_t(5), size_t(5000)}) {
        const std::vector<Triangle> tris = test::random_triangles(n, 11);
        const BuildTree one = build_binned_sah(tris, BuildConfig{}), many = build_binned_sah(tris, BuildConfig{}, 4);
        EXPECT_EQ(tree_hash(one), tree_hash(many)) << n << " triangles";
    }
}

TEST(FlattenIntoImage, Bvh2ImageFromTheTreeEqualsTheLongWay) {
    for (const auto& triangles : {test::clustered_triangles(3000, 5, 3), test::random_triangles(1, 2)}) {
        const Scene scene = test::make_scene(triangles);
        const BuildConfig config;
        const BuildTree tree = build_binned_sah(scene.triangles, config);
        const AccelImage direct = bvh2_image(tree, scene, config, "binned");
        const AccelImage long_way = bvh2_image(flatten_bvh(tree, scene, config), config, "binned");
        ASSERT_EQ(direct.regions.size(), long_way.regions.size());
        for (size_t r = 0; r < direct.regions.size(); ++r) {
            const Region &a = direct.regions[r], &b = long_way.regions[r];
            ASSERT_EQ(a.size_bytes(), b.size_bytes()) << a.name;
            EXPECT_EQ(a.base, b.base) << a.name;
            EXPECT_EQ(std::memcmp(a.bytes.data(), b.bytes.data(), a.size_bytes()), 0) << a.name;
        }
        EXPECT_EQ(direct.stats, long_way.stats);
    }
}

TEST(HwTriangleWriter, RecordsEqualMakeHwTriangleAndBadMaterialsAreNamed) {
    Material masked;
    masked.alpha_mode = AlphaMode::mask;
    masked.alpha_coverage = 0.37f;
    Scene scene = test::make_scene(test::random_triangles(50, 4), masked);
    const HwTriangleWriter write(scene);
    std::vector<uint32_t> prims;
    for (uint32_t p = 50; p-- > 0;) prims.push_back(p);
    std::vector<HwTriangle> out(prims.size());
    write.write(prims.data(), prims.size(), out.data());
    for (size_t i = 0; i < prims.size(); ++i) {
        const HwTriangle want = make_hw_triangle(scene, prims[i]);
        EXPECT_EQ(std::memcmp(&out[i], &want, sizeof want), 0) << "prim " << prims[i];
    }
    scene.tri_material[7] = 3;  // the scene has one material
    const std::string want = test::error_of([&] { make_hw_triangle(scene, 7); });
    EXPECT_NE(want.find("triangle 7 has material index 3"), std::string::npos) << want;
    EXPECT_EQ(test::error_of([&] { HwTriangleWriter{scene}(7); }), want);
}

}  // namespace
}  // namespace rtsim
