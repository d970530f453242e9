// Traversal against brute force on random scenes: zero differences in primitive id and in the
// bits of t (closest hit), and hit/miss agreement (any hit), including coincident triangles,
// axis-aligned triangles, alpha-MASK triangles, signed-zero directions and clipped intervals.
#include <algorithm>
#include <cstdio>

#include <gtest/gtest.h>

#include "isect_test_util.h"
#include "traces/accel/bvh2/bvh2.h"

namespace rtsim {
namespace {


Ray random_ray(Rng& rng) {
    Vec3 d = test::random_direction(rng);
    // Some directions with ±0 components (axis-parallel and in-plane rays).
    for (int a = 0; a < 3; ++a)
        if (rng.next() < 0.1f) d[a] = rng.next() < 0.5f ? 0.0f : -0.0f;
    if (d == Vec3(0.0f)) d.z = 1.0f;
    const Vec3 o = test::random_point(rng, Vec3(-6), Vec3(6));
    float tmin = 0.0f, tmax = std::numeric_limits<float>::infinity();
    if (rng.next() < 0.3f) {
        tmin = rng.next() * 4.0f;
        tmax = tmin + rng.next() * 8.0f;
    }
    return test::make_ray(o, d * (0.5f + rng.next()), tmin, tmax);
}

void compare(uint64_t seed, int triangles, uint32_t leaf_size, int rays) {
    const Scene scene = test::random_soup(seed, triangles);
    const HwBvh bvh = test::build(scene, leaf_size);
    Rng rng(seed * 31 + 1);
    int closest_diffs = 0, any_diffs = 0, hits = 0;
    for (int i = 0; i < rays; ++i) {
        const Ray r = random_ray(rng);
        const Hit a = trace_ray(bvh, r, TraversalMode::closest_hit);
        const Hit b = trace_ray_brute_force(bvh, r, TraversalMode::closest_hit);
        hits += a.valid();
        if (a.prim != b.prim || test::float_bits(a.t) != test::float_bits(b.t) ||
            test::float_bits(a.u) != test::float_bits(b.u)) {
            if (++closest_diffs < 5)
                std::printf("diff ray %d: traversal %d t=%a, brute %d t=%a\n", i, a.prim, a.t, b.prim, b.t);
        }
        const Hit c = trace_ray(bvh, r, TraversalMode::any_hit);
        const Hit d = trace_ray_brute_force(bvh, r, TraversalMode::any_hit);
        any_diffs += c.valid() != d.valid();
        if (c.valid() && !(c.t >= r.tmin && c.t <= r.tmax)) ++any_diffs;
    }
    std::printf("[ vs brute  ] seed %llu: %zu triangles, leaf %u, %d rays, %d hits, %d closest "
                "diffs, %d any-hit diffs\n",
                (unsigned long long)seed, scene.triangle_count(), leaf_size, rays, hits,
                closest_diffs, any_diffs);
    EXPECT_EQ(closest_diffs, 0);
    EXPECT_EQ(any_diffs, 0);
    EXPECT_GT(hits, rays / 50);
}

TEST(TraversalVsBruteForce, SmallLeaves) { compare(1, 3000, 1, 40000); }
TEST(TraversalVsBruteForce, DefaultLeaves) { compare(2, 3000, 4, 40000); }
TEST(TraversalVsBruteForce, ManySeeds) {
    for (uint64_t seed = 10; seed < 30; ++seed) compare(seed, 300, 2, 5000);
}

TEST(TraversalVsBruteForce, ClosedMeshesAndFeatureRays) {
    // Rays through the shared vertices of a closed mesh: many exact ties between neighbours.
    const std::vector<Vec3> soup = test::icosphere(2);
    const HwBvh bvh = test::build(test::make_scene(soup), 1);
    int diffs = 0;
    for (size_t k = 0; k < soup.size(); ++k) {
        for (const Vec3& o : {Vec3(0.0f), Vec3(0.25f, -0.125f, 0.0f), Vec3(3.0f, 0.0f, 0.0f)}) {
            const Ray r = test::make_ray(o, soup[k] - o);
            const Hit a = trace_ray(bvh, r, TraversalMode::closest_hit);
            const Hit b = trace_ray_brute_force(bvh, r, TraversalMode::closest_hit);
            const bool diff = a.prim != b.prim || test::float_bits(a.t) != test::float_bits(b.t);
            if (diff && diffs < 5)
                std::printf("diff k %zu: traversal %d t=%a, brute %d t=%a\n", k, a.prim, a.t, b.prim, b.t);
            diffs += diff;
        }
    }
    EXPECT_EQ(diffs, 0);
}

TEST(TraversalVsBruteForce, CubeGridVerticesFromManyOrigins) {
    // The tessellated cube: grid vertices are shared by up to 6 triangles in different leaves.
    const std::vector<Vec3> soup = test::tessellated_cube(6);
    const HwBvh bvh = test::build(test::make_scene(soup), 2);
    Rng rng(77);
    int diffs = 0, rays = 0;
    for (size_t k = 0; k < soup.size(); ++k)
        for (int j = 0; j < 4; ++j) {
            const Vec3 o = j == 0 ? Vec3(0.0f) : test::random_point(rng, Vec3(-3), Vec3(3));
            const Ray r = test::make_ray(o, soup[k] - o);
            const Hit a = trace_ray(bvh, r, TraversalMode::closest_hit);
            const Hit b = trace_ray_brute_force(bvh, r, TraversalMode::closest_hit);
            diffs += a.prim != b.prim || test::float_bits(a.t) != test::float_bits(b.t);
            ++rays;
        }
    EXPECT_EQ(rays, int(soup.size()) * 4);
    EXPECT_EQ(diffs, 0);
}

TEST(TraversalVsBruteForce, SteppingByHandEqualsTraceRay) {
    // trace_ray is the stepper in a loop: the same hit bits and the same work, ray by ray.
    const Scene scene = test::random_soup(5, 2000);
    const HwBvh bvh = test::build(scene);
    Rng rng(6);
    for (int i = 0; i < 5000; ++i) {
        const Ray r = random_ray(rng);
        for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
            Bvh2Stepper tr(bvh2_view(bvh));
            tr.begin(r, mode);
            int max_stack = 0;
            while (!tr.done()) {
                tr.execute();
                max_stack = std::max(max_stack, tr.stack_size());
            }
            WorkCounts w;
            const Hit h = trace_ray(bvh, r, mode, &w);
            ASSERT_EQ(h.prim, tr.hit().prim);
            ASSERT_EQ(test::float_bits(h.t), test::float_bits(tr.hit().t));
            ASSERT_EQ(w.steps, tr.work().steps);
            ASSERT_EQ(w.box_tests, 2 * w.steps);
            ASSERT_EQ(w.tri_tests, tr.work().tri_tests);
            ASSERT_EQ(w.anyhit_calls, tr.work().anyhit_calls);
            ASSERT_LE(max_stack, int(bvh.stats.max_depth) + 1);
        }
    }
}

TEST(TraversalVsBruteForce, PowerOfTwoScaledScenesHitTheSamePrims) {
    // Scene and rays scaled by 2^-20 (~1e-6) and 2^20 (~1e6): same prims, t unchanged (the
    // direction is not scaled), through separately built BVHs.
    const std::vector<Vec3> soup = test::icosphere(3);
    const HwBvh base = test::build(test::make_scene(soup));
    for (float s : {0x1p-20f, 0x1p20f}) {
        std::vector<Vec3> scaled = soup;
        for (Vec3& p : scaled) p *= s;
        const HwBvh bvh = test::build(test::make_scene(scaled));
        Rng rng(12);
        for (int i = 0; i < 20000; ++i) {
            const Vec3 o = test::random_point(rng, Vec3(-2), Vec3(2));
            const Vec3 d = test::random_direction(rng);
            const Hit a = trace_ray(base, test::make_ray(o, d), TraversalMode::closest_hit);
            const Hit b = trace_ray(bvh, test::make_ray(o * s, d * s), TraversalMode::closest_hit);
            ASSERT_EQ(a.prim, b.prim) << i;
            ASSERT_EQ(a.t, b.t) << i;
        }
    }
}

}  // namespace
}  // namespace rtsim
