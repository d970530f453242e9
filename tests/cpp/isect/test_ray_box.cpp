// Robust slab test (Ize 2013): signed zeros, rays in slab planes, empty slots, rounding.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "isect_test_util.h"
#include "traces/isect/ray_box.h"

namespace rtsim {
namespace {

using test::kInf;
using test::make_ray;

bool hit_box(const Ray& r, const Vec3& lo, const Vec3& hi, float* tn) {
    return intersect_box(ray_box_precompute(r), &lo.x, &hi.x, r.tmin, r.tmax, tn);
}

TEST(RayBox, SignedZeroKeepsItsInfinity) {
    const RayBoxPre pre = ray_box_precompute(make_ray(Vec3(0), Vec3(0.0f, -0.0f, 1.0f)));
    EXPECT_EQ(pre.inv_dir.x, kInf);
    EXPECT_EQ(pre.inv_dir.y, -kInf);
    EXPECT_EQ(pre.inv_dir.z, 1.0f);
}

TEST(RayBox, AllSixAxisDirectionsWithBothZeroSigns) {
    const Vec3 lo(-1), hi(1);
    for (int axis = 0; axis < 3; ++axis)
        for (float s : {1.0f, -1.0f})
            for (float z : {0.0f, -0.0f}) {
                Vec3 d(z);
                d[axis] = s;
                Vec3 o(0.5f);
                o[axis] = -3.0f * s;  // in front of the box, looking at it
                float tn = 0;
                ASSERT_TRUE(hit_box(make_ray(o, d), lo, hi, &tn)) << axis << " " << s;
                EXPECT_EQ(tn, 2.0f);
                // Beside the box on another axis: a miss, for +0 and -0 alike.
                Vec3 o2 = o;
                o2[(axis + 1) % 3] = 1.5f;
                EXPECT_FALSE(hit_box(make_ray(o2, d), lo, hi, &tn));
                o2[(axis + 1) % 3] = -1.5f;
                EXPECT_FALSE(hit_box(make_ray(o2, d), lo, hi, &tn));
                // Looking away: a miss.
                EXPECT_FALSE(hit_box(make_ray(o, -d), lo, hi, &tn));
            }
}

TEST(RayBox, RayLyingInAFacePlaneCountsAsInside) {
    // The origin is exactly on the plane x = 1 (0 * inf = NaN there), ray along z with dx = ±0.
    const Vec3 lo(-1), hi(1);
    float tn = 0;
    for (float z : {0.0f, -0.0f}) {
        EXPECT_TRUE(hit_box(make_ray(Vec3(1, 0, -5), Vec3(z, z, 1)), lo, hi, &tn));
        EXPECT_EQ(tn, 4.0f);
        EXPECT_TRUE(hit_box(make_ray(Vec3(-1, 0, -5), Vec3(z, 0.0f, 1)), lo, hi, &tn));
        EXPECT_TRUE(hit_box(make_ray(Vec3(1, 1, -5), Vec3(z, z, 1)), lo, hi, &tn));  // an edge
        EXPECT_FALSE(hit_box(make_ray(Vec3(std::nextafter(1.0f, 2.0f), 0, -5), Vec3(z, z, 1)), lo,
                             hi, &tn));
    }
    // A flat box (lo = hi on one axis), the ray inside its plane: inside.
    EXPECT_TRUE(hit_box(make_ray(Vec3(0, 0, -5), Vec3(0, 0, 1)), Vec3(-1, 0, -1), Vec3(1, 0, 1), &tn));
    // A flat box crossed by a ray: hit at the plane.
    EXPECT_TRUE(hit_box(make_ray(Vec3(0, -5, 0), Vec3(0, 1, 0)), Vec3(-1, 0, -1), Vec3(1, 0, 1), &tn));
    EXPECT_EQ(tn, 5.0f);
}

TEST(RayBox, OriginInsideGivesTmin) {
    float tn = -1;
    ASSERT_TRUE(hit_box(make_ray(Vec3(0), Vec3(0.3f, -0.2f, 1), 0.25f), Vec3(-1), Vec3(1), &tn));
    EXPECT_EQ(tn, 0.25f);
}

TEST(RayBox, IntervalClipsTheBox) {
    float tn = 0;
    EXPECT_FALSE(hit_box(make_ray(Vec3(0, 0, -5), Vec3(0, 0, 1), 0.0f, 3.9f), Vec3(-1), Vec3(1), &tn));
    EXPECT_TRUE(hit_box(make_ray(Vec3(0, 0, -5), Vec3(0, 0, 1), 0.0f, 4.0f), Vec3(-1), Vec3(1), &tn));
    EXPECT_FALSE(hit_box(make_ray(Vec3(0, 0, -5), Vec3(0, 0, 1), 6.1f, 9.0f), Vec3(-1), Vec3(1), &tn));
    EXPECT_TRUE(hit_box(make_ray(Vec3(0, 0, -5), Vec3(0, 0, 1), 6.0f, 9.0f), Vec3(-1), Vec3(1), &tn));
}

TEST(RayBox, EmptySlotNeverHits) {
    Rng rng(2);
    HwNode node{};
    for (int a = 0; a < 3; ++a) {
        node.lo(0, a) = -1.0f;
        node.hi(0, a) = 1.0f;
        node.lo(1, a) = kInf;
        node.hi(1, a) = -kInf;
    }
    const float zeros[2] = {0.0f, -0.0f};
    for (int i = 0; i < 20000; ++i) {
        Vec3 d = test::random_direction(rng);
        for (int a = 0; a < 3; ++a)
            if (rng.next() < 0.3f) d[a] = zeros[i & 1];
        if (d == Vec3(0.0f)) d.x = 1.0f;
        const Ray r = make_ray(test::random_point(rng, Vec3(-3), Vec3(3)), d, -1e30f, 1e30f);
        float tn[2];
        const unsigned mask = intersect_node_boxes(ray_box_precompute(r), node, r.tmin, r.tmax, tn);
        ASSERT_EQ(mask & 2u, 0u);
    }
}

TEST(RayBox, NeverMissesABoxARayTrulyCrosses) {
    // Rays through points on the surface of thin and far boxes (where rounding bites): the
    // widened far distance must keep every one of them a hit.
    Rng rng(4);
    for (int i = 0; i < 200000; ++i) {
        const float scale = std::ldexp(1.0f, int(rng.next() * 40.0f) - 20);
        const Vec3 lo = test::random_point(rng, Vec3(-1), Vec3(1)) * scale;
        Vec3 hi = lo + test::random_point(rng, Vec3(0), Vec3(1)) * scale;
        hi[i % 3] = lo[i % 3];  // a flat box
        // Away from the edges by 1%, so the rounded direction still crosses the box.
        const Vec3 target = lo + (hi - lo) * test::random_point(rng, Vec3(0.01f), Vec3(0.99f));
        const Vec3 o = target + test::random_direction(rng) * scale * 100.0f;
        float tn = 0;
        ASSERT_TRUE(hit_box(make_ray(o, target - o), lo, hi, &tn)) << i;
        ASSERT_LE(tn, 1.0f + 1e-5f);
    }
}

TEST(RayBox, NodeTestEqualsTwoBoxTestsBitForBit) {
    // The (SIMD) two-child node test must agree with the scalar one-box test on every bit,
    // including rays in slab planes (NaN slab distances), ±0 directions and flat boxes.
    Rng rng(8);
    const float grid[5] = {-1.0f, -0.5f, 0.0f, 0.5f, 1.0f};
    for (int i = 0; i < 200000; ++i) {
        HwNode node{};
        for (int c = 0; c < 2; ++c)
            for (int a = 0; a < 3; ++a) {
                float x = grid[int(rng.next() * 5) % 5], y = grid[int(rng.next() * 5) % 5];
                if (rng.next() < 0.5f) x = rng.next() * 2 - 1, y = rng.next() * 2 - 1;
                node.lo(c, a) = std::min(x, y);
                node.hi(c, a) = std::max(x, y);
            }
        Vec3 o, d;
        for (int a = 0; a < 3; ++a) {
            o[a] = rng.next() < 0.3f ? grid[int(rng.next() * 5) % 5] : rng.next() * 4 - 2;
            d[a] = rng.next() < 0.3f ? (rng.next() < 0.5f ? 0.0f : -0.0f) : rng.next() * 2 - 1;
        }
        if (d == Vec3(0.0f)) d.x = 1.0f;
        const Ray r = make_ray(o, d, rng.next() < 0.5f ? 0.0f : -1.0f, rng.next() < 0.5f ? kInf : 2.0f);
        const RayBoxPre pre = ray_box_precompute(r);
        float tn[2] = {0, 0}, t0 = 0, t1 = 0;
        const unsigned mask = intersect_node_boxes(pre, node, r.tmin, r.tmax, tn);
        const float lo0[3] = {node.lo(0, 0), node.lo(0, 1), node.lo(0, 2)};
        const float hi0[3] = {node.hi(0, 0), node.hi(0, 1), node.hi(0, 2)};
        const float lo1[3] = {node.lo(1, 0), node.lo(1, 1), node.lo(1, 2)};
        const float hi1[3] = {node.hi(1, 0), node.hi(1, 1), node.hi(1, 2)};
        const bool h0 = intersect_box(pre, lo0, hi0, r.tmin, r.tmax, &t0);
        const bool h1 = intersect_box(pre, lo1, hi1, r.tmin, r.tmax, &t1);
        ASSERT_EQ(mask, unsigned(h0) | (unsigned(h1) << 1)) << i;
        if (h0) {
            ASSERT_EQ(test::float_bits(tn[0]), test::float_bits(t0)) << i;
        }
        if (h1) {
            ASSERT_EQ(test::float_bits(tn[1]), test::float_bits(t1)) << i;
        }
    }
}

}  // namespace
}  // namespace rtsim
