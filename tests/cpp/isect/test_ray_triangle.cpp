// Watertight ray/triangle test (Woop et al. 2013): barycentrics, degenerates, grazing rays,
// rays starting on a surface, ties and scale.
#include <array>
#include <cmath>

#include <gtest/gtest.h>

#include "isect_test_util.h"
#include "traces/isect/ray_triangle.h"

namespace rtsim {
namespace {

using test::make_ray;

bool hit_tri(const Ray& r, const Vec3& a, const Vec3& b, const Vec3& c, TriangleHit* h) {
    return intersect_triangle(ray_triangle_precompute(r), &a.x, &b.x, &c.x, r.tmin, r.tmax, h);
}

TEST(RayTriangle, BarycentricsWeighVertex1AndVertex2) {
    const Vec3 a(0, 0, 5), b(4, 0, 5), c(0, 4, 5);
    TriangleHit h{};
    // Aim at a + 0.25 (b - a) + 0.5 (c - a) = (1, 2, 5).
    ASSERT_TRUE(hit_tri(make_ray(Vec3(1, 2, 0), Vec3(0, 0, 1)), a, b, c, &h));
    EXPECT_FLOAT_EQ(h.t, 5.0f);
    EXPECT_FLOAT_EQ(h.u, 0.25f);  // weight of v1
    EXPECT_FLOAT_EQ(h.v, 0.5f);   // weight of v2
    // Both windings and both ray directions hit (no backface culling).
    ASSERT_TRUE(hit_tri(make_ray(Vec3(1, 2, 0), Vec3(0, 0, 1)), a, c, b, &h));
    EXPECT_FLOAT_EQ(h.u, 0.5f);
    ASSERT_TRUE(hit_tri(make_ray(Vec3(1, 2, 10), Vec3(0, 0, -1)), a, b, c, &h));
    EXPECT_FLOAT_EQ(h.t, 5.0f);
    EXPECT_FLOAT_EQ(h.u, 0.25f);
    EXPECT_FALSE(hit_tri(make_ray(Vec3(5, 5, 0), Vec3(0, 0, 1)), a, b, c, &h));
}

TEST(RayTriangle, IntervalExcludesTminIncludesTmax) {
    const Vec3 a(-1, -1, 2), b(1, -1, 2), c(0, 1, 2);
    TriangleHit h{};
    EXPECT_FALSE(hit_tri(make_ray(Vec3(0), Vec3(0, 0, 1), 2.0f, 2.0f), a, b, c, &h));
    EXPECT_TRUE(hit_tri(make_ray(Vec3(0), Vec3(0, 0, 1), std::nextafter(2.0f, 0.0f), 2.0f), a, b, c, &h));
    EXPECT_FALSE(hit_tri(make_ray(Vec3(0), Vec3(0, 0, 1), 0.0f, std::nextafter(2.0f, 0.0f)), a, b, c, &h));
    EXPECT_FALSE(hit_tri(make_ray(Vec3(0), Vec3(0, 0, 1), std::nextafter(2.0f, 3.0f), 9.0f), a, b, c, &h));
    // Behind the origin: never with tmin = 0; yes with a negative tmin.
    EXPECT_FALSE(hit_tri(make_ray(Vec3(0, 0, 3), Vec3(0, 0, 1)), a, b, c, &h));
    ASSERT_TRUE(hit_tri(make_ray(Vec3(0, 0, 3), Vec3(0, 0, 1), -5.0f, 0.0f), a, b, c, &h));
    EXPECT_FLOAT_EQ(h.t, -1.0f);
}

TEST(RayTriangle, DegenerateTrianglesNeverHitNorNaN) {
    Rng rng(7);
    const Vec3 p(0.3f, -0.2f, 1.0f), q(1.7f, 0.9f, 2.5f);
    const std::vector<std::array<Vec3, 3>> degenerate = {
        {p, p, p},                                  // one point
        {p, p, q},                                  // repeated vertex
        {p, q, q},
        {Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(2, 2, 2)},      // collinear
        {Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(3, 0, 1)},      // collinear, axis-aligned
        {Vec3(0.1f, 0.2f, 0.3f), Vec3(0.2f, 0.4f, 0.6f), Vec3(0.4f, 0.8f, 1.2f)},
    };
    int tested = 0;
    for (const auto& tri : degenerate) {
        for (int i = 0; i < 20000; ++i) {
            // Aim at a random point on the segment(s) of the degenerate triangle.
            const float s = rng.next();
            const Vec3 target = tri[0] + s * (tri[2] - tri[0]) + 0.5f * s * (tri[1] - tri[0]);
            const Vec3 origin = target + 3.0f * test::random_direction(rng);
            TriangleHit h{-1, -1, -1};
            EXPECT_FALSE(hit_tri(make_ray(origin, target - origin), tri[0], tri[1], tri[2], &h));
            ASSERT_FALSE(std::isnan(h.t) || std::isnan(h.u) || std::isnan(h.v));
            ++tested;
        }
    }
    EXPECT_EQ(tested, 120000);
}

TEST(RayTriangle, SliversAreWatertightNotNaN) {
    // A sliver 1e-7 wide: hits inside it are fine, but never NaN and always inside [0, inf].
    const Vec3 a(0, 0, 1), b(1, 0, 1), c(1, 1e-7f, 1);
    Rng rng(3);
    int hits = 0;
    for (int i = 0; i < 20000; ++i) {
        const Vec3 o(rng.next(), rng.next() * 2e-7f - 0.5e-7f, 0.0f);
        TriangleHit h{};
        if (hit_tri(make_ray(o, Vec3(0, 0, 1)), a, b, c, &h)) {
            ++hits;
            ASSERT_EQ(h.t, 1.0f);
            ASSERT_TRUE(h.u >= 0.0f && h.v >= 0.0f && h.u + h.v <= 1.0001f);
        }
    }
    EXPECT_GT(hits, 0);
    EXPECT_LT(hits, 20000);
}

TEST(RayTriangle, GrazingRaysAreStable) {
    // Rays nearly parallel to the plane z = 1: a hit must lie on the triangle, never NaN.
    const Vec3 a(-10, -10, 1), b(10, -10, 1), c(0, 10, 1);
    Rng rng(11);
    int hits = 0;
    for (int i = 0; i < 50000; ++i) {
        const float eps = std::ldexp(1.0f, -int(rng.next() * 40.0f));
        const Vec3 o(-20.0f, rng.next() * 10.0f - 5.0f, 1.0f - eps * 20.0f);
        const Vec3 d(1.0f, rng.next() * 0.1f - 0.05f, eps);
        TriangleHit h{};
        if (hit_tri(make_ray(o, d), a, b, c, &h)) {
            ++hits;
            ASSERT_TRUE(std::isfinite(h.t) && h.t >= 0.0f);
            const Vec3 p = o + h.t * d;
            ASSERT_NEAR(p.z, 1.0f, 1e-4f);
            ASSERT_TRUE(p.x >= -10.01f && p.x <= 10.01f);
        }
    }
    EXPECT_GT(hits, 1000);
    // Exactly parallel and in the plane: the 2D triangle degenerates to a line, det = 0.
    TriangleHit h{};
    EXPECT_FALSE(hit_tri(make_ray(Vec3(-20, 0, 1), Vec3(1, 0, 0)), a, b, c, &h));
    EXPECT_FALSE(hit_tri(make_ray(Vec3(-20, 0, 1.5f), Vec3(1, 0, 0)), a, b, c, &h));
}

TEST(RayTriangle, RayStartingOnTheSurface) {
    // Documented: tmin is excluded, so a ray starting on the surface does not hit it at t = 0.
    const Vec3 a(-1, -1, 0), b(1, -1, 0), c(0, 1, 0);
    TriangleHit h{};
    EXPECT_FALSE(hit_tri(make_ray(Vec3(0.1f, 0.2f, 0.0f), Vec3(0.3f, 0.1f, 1.0f)), a, b, c, &h));
    // Also for an origin at exactly 0 in the plane x = 0 (zero rounding error, zero offset).
    EXPECT_FALSE(hit_tri(make_ray(Vec3(0.0f, 0.2f, 0.3f), Vec3(1.0f, 0.1f, 0.2f)), Vec3(0, -1, -1),
                         Vec3(0, 1, -1), Vec3(0, 0, 1), &h));
    // Starting just before the surface still hits it.
    ASSERT_TRUE(hit_tri(make_ray(Vec3(0.1f, 0.2f, -1e-3f), Vec3(0.3f, 0.1f, 1.0f)), a, b, c, &h));
    EXPECT_GT(h.t, 0.0f);
    // Leaving the surface with tmin > 0 (the usual offset): no self-hit.
    EXPECT_FALSE(hit_tri(make_ray(Vec3(0.1f, 0.2f, 0.0f), Vec3(0.3f, 0.1f, 1.0f), 1e-4f), a, b,
                         c, &h));
    // An origin offset along the normal: no self-hit either.
    EXPECT_FALSE(hit_tri(make_ray(Vec3(0.1f, 0.2f, 1e-4f), Vec3(0.3f, 0.1f, 1.0f)), a, b, c, &h));
}

TEST(RayTriangle, ScaleInvarianceAtPowerOfTwoScales) {
    // The same triangles scaled by 2^-20 (~1e-6) and 2^20 (~1e6): every product scales exactly,
    // so hits and t scale exactly too (no underflow or overflow at these scales).
    Rng rng(5);
    int hits = 0;
    for (int i = 0; i < 20000; ++i) {
        const Vec3 a = test::random_point(rng, Vec3(-1), Vec3(1)), b = test::random_point(rng, Vec3(-1), Vec3(1)),
                   c = test::random_point(rng, Vec3(-1), Vec3(1));
        const Vec3 o = 3.0f * test::random_direction(rng);
        const Vec3 d = test::random_point(rng, Vec3(-0.5f), Vec3(0.5f)) - o;
        TriangleHit h1{}, h2{}, h3{};
        const bool r1 = hit_tri(make_ray(o, d), a, b, c, &h1);
        for (float s : {0x1p-20f, 0x1p20f}) {
            TriangleHit& hs = s < 1.0f ? h2 : h3;
            const bool rs = hit_tri(make_ray(o * s, d), a * s, b * s, c * s, &hs);
            ASSERT_EQ(r1, rs);
            if (r1) {
                ASSERT_EQ(h1.t * s, hs.t);
            }
        }
        hits += r1;
    }
    EXPECT_GT(hits, 1000);
}

TEST(RayTriangle, DecimalScalesKeepHitPrimitives) {
    // Scaled by 1e-6 and 1e6 (inexact): rays aimed at centroids still hit the same triangle.
    Rng rng(9);
    for (float s : {1e-6f, 1e6f}) {
        for (int i = 0; i < 20000; ++i) {
            const Vec3 a = test::random_point(rng, Vec3(-1), Vec3(1)), b = test::random_point(rng, Vec3(-1), Vec3(1)),
                       c = test::random_point(rng, Vec3(-1), Vec3(1));
            const Vec3 centroid = (a + b + c) / 3.0f;
            const Vec3 o = 3.0f * test::random_direction(rng);
            TriangleHit h{};
            // Skip near-edge-on triangles, where the centroid is within rounding of an edge.
            const Vec3 n = glm::cross(b - a, c - a);
            if (std::fabs(glm::dot(glm::normalize(n), glm::normalize(centroid - o))) < 1e-3f) continue;
            ASSERT_TRUE(hit_tri(make_ray(o * s, (centroid - o) * s), a * s, b * s, c * s, &h));
            ASSERT_NEAR(h.t, 1.0f, 1e-4f);
        }
    }
}

}  // namespace
}  // namespace rtsim
