// Ray/capsule test (ray_capsule_kernel.h): body, caps and the seam between them, rays along the
// axis, from inside and from the surface, tangent and grazing rays, a capsule of zero length as
// its sphere, huge coordinates, and random rays checked against the capsule's distance function
// in long double (a hit lies on the surface with the ray outside before it; a miss never comes
// within the radius of the axis).
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "isect_test_util.h"
#include "traces/common/rng.h"
#include "traces/isect/leaf_kernel.h"

namespace rtsim {
namespace {

using test::make_ray;

bool hit_capsule(const Ray& r, const Vec3& a, const Vec3& b, float radius, TriangleHit* h) {
    return detail::capsule_kernel(ray_triangle_precompute(r), &a.x, &b.x, radius, r.tmin, r.tmax, h);
}

const Vec3 kA(0, 0, -1), kB(0, 0, 1);

TEST(RayCapsule, BodyCapsAndTheSeam) {
    TriangleHit h{};
    ASSERT_TRUE(hit_capsule(make_ray(Vec3(-5, 0, 0), Vec3(1, 0, 0)), kA, kB, 0.5f, &h));  // the body
    EXPECT_FLOAT_EQ(h.t, 4.5f);
    EXPECT_FLOAT_EQ(h.u, 0.5f);
    ASSERT_TRUE(hit_capsule(make_ray(Vec3(0, 0, -5), Vec3(0, 0, 1)), kA, kB, 0.5f, &h));  // along the axis
    EXPECT_FLOAT_EQ(h.t, 3.5f);
    EXPECT_FLOAT_EQ(h.u, 0.0f);
    ASSERT_TRUE(hit_capsule(make_ray(Vec3(0.3f, 0, -5), Vec3(0, 0, 1)), kA, kB, 0.5f, &h));  // a cap off-axis
    EXPECT_NEAR(h.t, 5.0f - 1.0f - 0.4f, 1e-6f);
    ASSERT_TRUE(hit_capsule(make_ray(Vec3(-5, 0, -1), Vec3(1, 0, 0)), kA, kB, 0.5f, &h));  // the seam
    EXPECT_FLOAT_EQ(h.t, 4.5f);
    ASSERT_TRUE(hit_capsule(make_ray(Vec3(-5, 0, 1.3f), Vec3(1, 0, 0)), kA, kB, 0.5f, &h));  // cap B's side
    EXPECT_NEAR(h.t, 5.0f - 0.4f, 1e-6f);
    EXPECT_FALSE(hit_capsule(make_ray(Vec3(-5, 0, 1.6f), Vec3(1, 0, 0)), kA, kB, 0.5f, &h));  // beyond it
    EXPECT_FALSE(hit_capsule(make_ray(Vec3(-5, 0, 0), Vec3(-1, 0, 0)), kA, kB, 0.5f, &h));    // behind
}

TEST(RayCapsule, FromInsideAndFromTheSurface) {
    TriangleHit h{};
    ASSERT_TRUE(hit_capsule(make_ray(Vec3(0), Vec3(1, 0, 0)), kA, kB, 0.5f, &h));
    EXPECT_FLOAT_EQ(h.t, 0.5f);
    ASSERT_TRUE(hit_capsule(make_ray(Vec3(0), Vec3(0, 0, 1)), kA, kB, 0.5f, &h));  // out through a cap
    EXPECT_FLOAT_EQ(h.t, 1.5f);
    // Spawned on the body (tmin = 0 excluded): outward misses, inward crosses to the far side.
    EXPECT_FALSE(hit_capsule(make_ray(Vec3(0.5f, 0, 0), Vec3(1, 0, 0)), kA, kB, 0.5f, &h));
    ASSERT_TRUE(hit_capsule(make_ray(Vec3(0.5f, 0, 0), Vec3(-1, 0, 0)), kA, kB, 0.5f, &h));
    EXPECT_FLOAT_EQ(h.t, 1.0f);
}

TEST(RayCapsule, TangentAndGrazingRays) {
    TriangleHit h{};
    ASSERT_TRUE(hit_capsule(make_ray(Vec3(-5, 0.5f, 0), Vec3(1, 0, 0)), kA, kB, 0.5f, &h));
    EXPECT_FLOAT_EQ(h.t, 5.0f);
    EXPECT_FALSE(hit_capsule(make_ray(Vec3(-5, std::nextafter(0.5f, 1.0f), 0), Vec3(1, 0, 0)), kA, kB, 0.5f, &h));
    // Parallel to the axis on the body's surface, and just inside it: the caps' rims.
    ASSERT_TRUE(hit_capsule(make_ray(Vec3(std::nextafter(0.5f, 0.0f), 0, -5), Vec3(0, 0, 1)), kA, kB, 0.5f, &h));
    EXPECT_NEAR(h.t, 4.0f, 1e-3f);
    EXPECT_TRUE(std::isfinite(h.u) && std::isfinite(h.v));
    EXPECT_FALSE(hit_capsule(make_ray(Vec3(std::nextafter(0.5f, 1.0f), 0, -5), Vec3(0, 0, 1)), kA, kB, 0.5f, &h));
}

TEST(RayCapsule, ZeroLengthIsItsSphereAndDegenerateRadiiMiss) {
    Rng rng(3);
    for (int i = 0; i < 20000; ++i) {
        const Ray r = make_ray(Vec3(6 * rng.next() - 3, 6 * rng.next() - 3, 6 * rng.next() - 3),
                               Vec3(2 * rng.next() - 1, 2 * rng.next() - 1, 2 * rng.next() - 1));
        const Vec3 c(0.1f, 0.2f, 0.3f);
        TriangleHit a{}, b{};
        const bool cap = hit_capsule(r, c, c, 1.0f, &a);
        const bool sph = detail::sphere_kernel(ray_triangle_precompute(r), &c.x, 1.0f, r.tmin, r.tmax, &b);
        ASSERT_EQ(cap, sph) << i;
        if (cap) EXPECT_FLOAT_EQ(a.t, b.t) << i;
    }
    TriangleHit h{};
    for (float radius : {0.0f, -1.0f, std::nanf(""), INFINITY})
        EXPECT_FALSE(hit_capsule(make_ray(Vec3(-5, 0, 0), Vec3(1, 0, 0)), kA, kB, radius, &h)) << radius;
}

TEST(RayCapsule, HugeCoordinatesKeepTheirDigits) {
    TriangleHit h{};
    const Vec3 a(1e6f, 2e6f, -3e6f), b = a + Vec3(0, 0, 1e-2f);
    ASSERT_TRUE(hit_capsule(make_ray(a + Vec3(-10, 0, 5e-3f), Vec3(1, 0, 0)), a, b, 1e-3f, &h));
    EXPECT_NEAR(h.t, 10.0f - 1e-3f, 1e-5f);
}

/// Distance of p to the segment a-b, minus r: the capsule's signed distance, in long double.
long double capsule_sdf(const Vec3& p, const Vec3& a, const Vec3& b, float r) {
    const long double ax = a.x, ay = a.y, az = a.z;
    const long double bx = b.x - ax, by = b.y - ay, bz = b.z - az, px = p.x - ax, py = p.y - ay, pz = p.z - az;
    long double s = (px * bx + py * by + pz * bz) / (bx * bx + by * by + bz * bz);
    s = s < 0 ? 0 : (s > 1 ? 1 : s);
    const long double dx = px - s * bx, dy = py - s * by, dz = pz - s * bz;
    return std::sqrt(dx * dx + dy * dy + dz * dz) - r;
}

TEST(RayCapsule, AgreesWithTheDistanceFunctionOnRandomRays) {
    Rng rng(7);
    int hits = 0, misses = 0;
    for (int i = 0; i < 20000; ++i) {
        const Vec3 a(2 * rng.next() - 1, 2 * rng.next() - 1, 2 * rng.next() - 1);
        const Vec3 b = a + Vec3(2 * rng.next() - 1, 2 * rng.next() - 1, 2 * rng.next() - 1);
        const float r = 0.05f + 0.5f * rng.next();
        const Vec3 o(10 * rng.next() - 5, 10 * rng.next() - 5, 10 * rng.next() - 5);
        const Vec3 target = a + rng.next() * (b - a) + Vec3(rng.next() - 0.5f, rng.next() - 0.5f, rng.next() - 0.5f);
        if (capsule_sdf(o, a, b, r) <= 1e-3L) continue;  // origins outside
        const Ray ray = make_ray(o, target - o);
        TriangleHit h{};
        // The ray's closest approach to the axis, by ternary search (the distance is convex in t).
        long double lo = 0, hi = 1e3;
        auto at = [&](long double t) { return capsule_sdf(o + float(t) * ray.direction, a, b, r); };
        for (int k = 0; k < 200; ++k) {
            const long double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3;
            (at(m1) < at(m2) ? hi : lo) = (at(m1) < at(m2) ? m2 : m1);
        }
        const long double closest = at(lo);
        const long double scale = glm::length(ray.direction);
        if (hit_capsule(ray, a, b, r, &h)) {
            ++hits;
            EXPECT_NEAR(double(at(h.t)), 0.0, 1e-5 * std::max(1.0, double(h.t * scale))) << i;
            EXPECT_GT(double(at(h.t * (1.0L - 1e-4L))), -1e-6) << i << ": an earlier crossing";
        } else {
            ++misses;
            EXPECT_GT(double(closest), -1e-5) << i << ": the ray enters the capsule but was not hit";
        }
    }
    EXPECT_GT(hits, 3000);
    EXPECT_GT(misses, 3000);
}

TEST(RayCapsule, LeafKernelDispatchesAndCountsCapsules) {
    const HwTriangle rec{{0, 0, -1}, {0, 0, 1}, {0.5f, 0, 0}, 7, 0, kPrimCapsule};
    const Ray r = make_ray(Vec3(-5, 0, 0), Vec3(1, 0, 0));
    TriangleHit h{};
    ASSERT_TRUE(detail::primitive_kernel(ray_triangle_precompute(r), rec, r.tmin, r.tmax, &h));
    EXPECT_FLOAT_EQ(h.t, 4.5f);
    const detail::LeafTests t = detail::leaf_tests(&rec, 1, true);
    EXPECT_EQ(t.capsules, 1u);
    EXPECT_EQ(t.triangles + t.spheres, 0u);
}

}  // namespace
}  // namespace rtsim
