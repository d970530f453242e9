// The SBVH builder (Stich et al. 2009): tree invariants with duplicated references (every
// primitive covered by its leaf boxes), lower SAH cost than binned SAH where triangles are long
// and overlapping, the reference budget and the overlap threshold, determinism, the depth bound,
// the clipping's conservative boxes, and config errors. A disabled benchmark prints Sponza.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <gtest/gtest.h>

#include "bvh_test_scenes.h"
#include "traces/bvh/builder.h"
#include "traces/bvh/sbvh_builder.h"
#include "traces/bvh/sbvh_clip.h"
#include "traces/common/error.h"
#include "traces/scene/gltf_loader.h"

namespace rtsim {
namespace {

using test::make_scene;

/// Long thin triangles at random orientations across [0, 10]^3: their boxes are mostly empty
/// and overlap everywhere, the case spatial splits are for.
std::vector<Triangle> long_triangles(size_t count, uint64_t seed) {
    Rng rng(seed);
    std::vector<Triangle> out;
    for (size_t i = 0; i < count; ++i) {
        const Vec3 a(rng.next() * 10, rng.next() * 10, rng.next() * 10), b(rng.next() * 10, rng.next() * 10, rng.next() * 10);
        const Vec3 w(rng.next() * 0.1f, rng.next() * 0.1f, rng.next() * 0.1f);
        out.push_back(Triangle{a, b, a + w});
    }
    return out;
}

HwBvh build(const Scene& scene, const SbvhConfig& s = {}, SbvhStats* stats = nullptr, const BuildConfig& c = {}) {
    return flatten_bvh(build_sbvh(scene.triangles, c, s, stats), scene, c);
}

TEST(SbvhBuild, InvariantsHoldWithDuplicatedReferences) {
    for (uint64_t seed : {1, 2, 3}) {
        const Scene scene = make_scene(long_triangles(400, seed));
        SbvhStats stats;
        const HwBvh bvh = build(scene, {}, &stats);
        EXPECT_NO_THROW(check_bvh_invariants(bvh, scene, true)) << seed;
        EXPECT_GT(stats.spatial_splits, 0u);
        EXPECT_GT(bvh.triangles.size(), scene.triangles.size());  // references were duplicated
        EXPECT_EQ(bvh.triangles.size(), stats.references);
        EXPECT_LE(stats.references, 2 * scene.triangles.size());  // the default budget: 2N
        EXPECT_LE(bvh.stats.max_depth, 64u);
        EXPECT_LE(bvh.stats.max_leaf_size, 4u);
        // The strict (binned) rules refuse the same tree: a primitive is stored twice.
        EXPECT_THROW(check_bvh_invariants(bvh, scene), Error);
    }
}

TEST(SbvhBuild, LowerSahCostThanBinnedOnOverlappingTriangles) {
    const Scene scene = make_scene(long_triangles(3000, 7));
    const HwBvh binned = build_bvh(scene);
    const HwBvh sbvh = build(scene);
    std::printf("[ sbvh ] long triangles: SAH binned %.2f, sbvh %.2f (%.2fx), %zu -> %zu records\n",
                binned.stats.sah_cost, sbvh.stats.sah_cost, sbvh.stats.sah_cost / binned.stats.sah_cost,
                binned.triangles.size(), sbvh.triangles.size());
    EXPECT_LT(sbvh.stats.sah_cost, 0.95 * binned.stats.sah_cost);  // measured 0.89x
    // Compact, non-overlapping triangles: no budget spent, and about binned's cost.
    const Scene compact = make_scene(test::random_triangles(3000, 8));
    SbvhStats stats;
    const HwBvh c = build(compact, {}, &stats);
    EXPECT_LT(double(stats.references), 1.05 * 3000.0);
    EXPECT_LT(c.stats.sah_cost, 1.05 * build_bvh(compact).stats.sah_cost);
}

TEST(SbvhBuild, BudgetAndOverlapThresholdLimitSpatialSplits) {
    const Scene scene = make_scene(long_triangles(1000, 4));
    const size_t n = scene.triangles.size();
    SbvhConfig none;
    none.reference_budget = 0.0f;
    SbvhStats stats;
    HwBvh bvh = build(scene, none, &stats);
    EXPECT_EQ(stats.spatial_splits, 0u);
    EXPECT_EQ(bvh.triangles.size(), n);
    EXPECT_NO_THROW(check_bvh_invariants(bvh, scene));  // the strict rules hold: no duplicate
    for (float budget : {0.05f, 0.25f}) {
        SbvhConfig some;
        some.reference_budget = budget;
        build(scene, some, &stats);
        EXPECT_GT(stats.references, n);
        EXPECT_LE(double(stats.references), double(n) * (1.0 + double(budget))) << budget;
    }
    // A higher alpha tries spatial splits in fewer nodes: fewer of them, fewer references.
    SbvhStats low, high;
    SbvhConfig strict;
    strict.alpha = 0.05f;
    build(scene, {}, &low);
    build(scene, strict, &high);
    EXPECT_LT(high.spatial_splits, low.spatial_splits);
    EXPECT_LT(high.references, low.references);
    // Unsplitting keeps some straddlers whole.
    EXPECT_GT(low.unsplit, 0u);
}

TEST(SbvhBuild, DeterministicAndDepthBounded) {
    const Scene scene = make_scene(long_triangles(600, 9));
    const BuildTree a = build_sbvh(scene.triangles, BuildConfig{}), b = build_sbvh(scene.triangles, BuildConfig{});
    ASSERT_EQ(a.prim_ids, b.prim_ids);
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    for (size_t i = 0; i < a.nodes.size(); ++i) {
        EXPECT_EQ(a.nodes[i].box.lo, b.nodes[i].box.lo);
        EXPECT_EQ(a.nodes[i].box.hi, b.nodes[i].box.hi);
    }
    // Triangles at x = 1.1^i make a chain under SAH; the guard keeps every leaf within max_depth.
    std::vector<Triangle> chain;
    for (int i = 0; i < 900; ++i) {
        const float x = std::pow(1.1f, float(i)), s = x * 0.5f;
        chain.push_back(Triangle{Vec3(x, 0, 0), Vec3(x + s, s, 0), Vec3(x, 0, s)});
    }
    const Scene deep = make_scene(chain);
    for (uint32_t max_depth : {64u, 16u}) {
        BuildConfig c;
        c.max_depth = max_depth;
        const HwBvh bvh = build(deep, {}, nullptr, c);
        EXPECT_LE(bvh.stats.max_depth, max_depth);
        EXPECT_NO_THROW(check_bvh_invariants(bvh, deep, true));
    }
}

TEST(SbvhBuild, CheckerCatchesALeafBoxThatNoLongerCoversItsTriangle) {
    const Scene scene = make_scene(long_triangles(200, 5));
    const HwBvh good = build(scene);
    int caught = 0;
    // Halve leaf boxes along their longest axis (still inside the parent): the part of a
    // triangle that stuck out of the other half is left uncovered.
    for (size_t i = 0; i < good.nodes.size() && caught == 0; ++i)
        for (int slot = 0; slot < 2; ++slot) {
            if (good.nodes[i].child_count[slot] == 0 || good.nodes[i].child_count[slot] == kEmptyChild) continue;
            HwBvh bad = good;
            HwNode& n = bad.nodes[i];
            Vec3 e(n.hi(slot, 0) - n.lo(slot, 0), n.hi(slot, 1) - n.lo(slot, 1), n.hi(slot, 2) - n.lo(slot, 2));
            const int a = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
            n.hi(slot, a) = n.lo(slot, a) + 0.5f * e[a];
            try {
                check_bvh_invariants(bad, scene, true);
            } catch (const Error& err) {
                caught += std::string(err.what()).find("leaf boxes cover") != std::string::npos;
            }
        }
    EXPECT_GT(caught, 0);
}

TEST(SbvhClip, PiecesAreConservativeAndCoverTheTriangle) {
    Rng rng(3);
    for (int i = 0; i < 2000; ++i) {
        Triangle t{Vec3(rng.next(), rng.next(), rng.next()) * 8.0f - 4.0f, Vec3(rng.next(), rng.next(), rng.next()) * 8.0f - 4.0f,
                   Vec3(rng.next(), rng.next(), rng.next()) * 8.0f - 4.0f};
        if (i % 5 == 0) t.v2.x = t.v1.x = t.v0.x;  // axis-aligned
        Aabb box;
        box.grow(t.v0), box.grow(t.v1), box.grow(t.v2);
        const ClippedTriangle whole(t, box);
        const int axis = i % 3;
        const float s = box.lo[axis] + (box.hi[axis] - box.lo[axis]) * rng.next();
        Aabb left, right;
        whole.split(axis, s, &left, &right);
        ASSERT_TRUE(box.contains(left) && box.contains(right));
        EXPECT_LE(left.hi[axis], s);
        EXPECT_GE(right.lo[axis], s);
        // The pieces' areas add up to the triangle's (within double rounding).
        const double a = whole.area(), al = left.empty() ? 0.0 : ClippedTriangle(t, left).area(),
                     ar = right.empty() ? 0.0 : ClippedTriangle(t, right).area();
        EXPECT_GE(al + ar, a * (1.0 - 1e-9)) << i;
        // Chopping into 8 slabs (boxes rounded to nearest, for binning): the same coverage.
        float planes[9];
        for (int k = 0; k <= 8; ++k) planes[k] = k == 8 ? box.hi[axis] : box.lo[axis] + float(k) * (box.hi[axis] - box.lo[axis]) / 8.0f;
        Aabb pieces[8];
        whole.chop(axis, planes, 8, pieces);
        double sum = 0.0;
        for (int k = 0; k < 8; ++k)
            if (!pieces[k].empty()) {
                EXPECT_GE(pieces[k].lo[axis], planes[k]);
                EXPECT_LE(pieces[k].hi[axis], planes[k + 1]);
                sum += ClippedTriangle(t, pieces[k]).area();
            }
        EXPECT_GE(sum, a * (1.0 - 1e-5)) << i;
    }
}

TEST(SbvhBuild, ConfigErrorsNameTheField) {
    const std::vector<Triangle> tris = long_triangles(10, 1);
    SbvhConfig c;
    c.spatial_bins = 1;
    EXPECT_THROW(build_sbvh(tris, BuildConfig{}, c), Error);
    c = SbvhConfig{};
    c.reference_budget = -1.0f;
    EXPECT_THROW(build_sbvh(tris, BuildConfig{}, c), Error);
    std::vector<Triangle> bad = tris;
    bad[3].v1.y = std::nanf("");
    try {
        build_sbvh(bad, BuildConfig{});
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("triangle 3 has a non-finite vertex"), std::string::npos);
    }
}

TEST(SbvhBenchmark, DISABLED_Sponza) {
    const std::string path = std::string(RTSIM_SCENES_DIR) + "/sponza/Sponza.gltf";
    if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not found";
    const Scene scene = load_gltf(path);
    const HwBvh binned = build_bvh(scene);
    SbvhStats stats;
    const HwBvh sbvh = build(scene, {}, &stats);
    std::printf("Sponza: SAH binned %.2f, sbvh %.2f (%.3fx); %zu -> %zu records; %llu spatial, %llu object splits\n",
                binned.stats.sah_cost, sbvh.stats.sah_cost, sbvh.stats.sah_cost / binned.stats.sah_cost,
                binned.triangles.size(), sbvh.triangles.size(), (unsigned long long)stats.spatial_splits,
                (unsigned long long)stats.object_splits);
    EXPECT_NO_THROW(check_bvh_invariants(sbvh, scene, true));
}

}  // namespace
}  // namespace rtsim
