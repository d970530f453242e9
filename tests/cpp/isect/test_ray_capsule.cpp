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

bool hit_capsule(const Ray& r, const Vec3& a, const Vec3& b, float r0, float r1, TriangleHit* h) {
    return detail::capsule_kernel(ray_triangle_precompute(r), &a.x, &b.x, r0, r1, r.tmin, r.tmax, h);
}
bool hit_capsule(const Ray& r, const Vec3& a, const Vec3& b, float radius, TriangleHit* h) {
    return hit_capsule(r, a, b, radius, radius, h);
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

/// The signed distance of p to the sphere swept from a (radius r0) to b (radius r1), in long
/// double: the swept sphere nearest p in the sense of |p - c(s)| - r(s), convex in s, whose
/// minimiser is s = y + q k / sqrt(1 - k^2) clamped to the segment (y along the axis, q across it,
/// k = (r1 - r0) / L); |k| >= 1 is the larger end sphere.
long double capsule_sdf(const Vec3& p, const Vec3& a, const Vec3& b, float r0, float r1) {
    const long double bx = (long double)b.x - a.x, by = (long double)b.y - a.y, bz = (long double)b.z - a.z;
    const long double px = (long double)p.x - a.x, py = (long double)p.y - a.y, pz = (long double)p.z - a.z;
    const long double length = std::sqrt(bx * bx + by * by + bz * bz), k = ((long double)r1 - r0) / length;
    long double s;  // along the axis, 0 to length
    if (std::fabs(k) >= 1) {
        s = r1 > r0 ? length : 0;
    } else {
        const long double y = (px * bx + py * by + pz * bz) / length;
        const long double qx = px - y * bx / length, qy = py - y * by / length, qz = pz - y * bz / length;
        s = y + std::sqrt(qx * qx + qy * qy + qz * qz) * k / std::sqrt(1 - k * k);
        s = s < 0 ? 0 : (s > length ? length : s);
    }
    const long double dx = px - s * bx / length, dy = py - s * by / length, dz = pz - s * bz / length;
    return std::sqrt(dx * dx + dy * dy + dz * dz) - (r0 + (std::fabs(k) >= 1 ? (r1 > r0 ? r1 - r0 : 0) : k * s));
}

/// 20,000 random capsules (every other one of two radii, some whose larger end sphere holds the
/// other) and rays from outside, each checked against the distance function: a hit lies on the
/// surface with no earlier crossing; a miss never enters.
void check_against_distance(uint64_t seed, bool two_radii) {
    Rng rng(seed);
    int hits = 0, misses = 0;
    for (int i = 0; i < 20000; ++i) {
        const Vec3 a(2 * rng.next() - 1, 2 * rng.next() - 1, 2 * rng.next() - 1);
        const Vec3 b = a + Vec3(2 * rng.next() - 1, 2 * rng.next() - 1, 2 * rng.next() - 1);
        const float r0 = 0.05f + 0.5f * rng.next(), r1 = two_radii ? 0.02f + 0.6f * rng.next() : r0;
        const Vec3 o(10 * rng.next() - 5, 10 * rng.next() - 5, 10 * rng.next() - 5);
        const Vec3 target = a + rng.next() * (b - a) + Vec3(rng.next() - 0.5f, rng.next() - 0.5f, rng.next() - 0.5f);
        if (capsule_sdf(o, a, b, r0, r1) <= 1e-3L) continue;  // origins outside
        const Ray ray = make_ray(o, target - o);
        TriangleHit h{};
        // The ray's closest approach, by ternary search (the distance is convex in t).
        long double lo = 0, hi = 1e3;
        auto at = [&](long double t) { return capsule_sdf(o + float(t) * ray.direction, a, b, r0, r1); };
        for (int k = 0; k < 200; ++k) {
            const long double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3;
            (at(m1) < at(m2) ? hi : lo) = (at(m1) < at(m2) ? m2 : m1);
        }
        const long double closest = at(lo);
        const long double scale = glm::length(ray.direction);
        if (hit_capsule(ray, a, b, r0, r1, &h)) {
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

TEST(RayCapsule, AgreesWithTheDistanceFunctionOnRandomRays) { check_against_distance(7, false); }

TEST(RayCapsule, TwoRadiiAgreeWithTheDistanceFunctionOnRandomRays) { check_against_distance(11, true); }

// A round cone from radius 0.5 at z = -1 to 0.25 at z = 1: k = -1/8, c = sqrt(63/64); its
// body at axial coordinate y (from a) has radius (0.5 + k y) / c.
TEST(RayCapsule, TwoRadiiBodyCapsAndContact) {
    TriangleHit h{};
    const double k = -0.125, c = std::sqrt(1.0 - k * k);
    ASSERT_TRUE(hit_capsule(make_ray(Vec3(-5, 0, 0), Vec3(1, 0, 0)), kA, kB, 0.5f, 0.25f, &h));  // the body
    EXPECT_NEAR(h.t, 5.0 - (0.5 + k * 1.0) / c, 1e-6);
    ASSERT_TRUE(hit_capsule(make_ray(Vec3(0, 0, -5), Vec3(0, 0, 1)), kA, kB, 0.5f, 0.25f, &h));  // a's cap
    EXPECT_FLOAT_EQ(h.t, 3.5f);
    ASSERT_TRUE(hit_capsule(make_ray(Vec3(0, 0, 5), Vec3(0, 0, -1)), kA, kB, 0.5f, 0.25f, &h));  // b's cap
    EXPECT_FLOAT_EQ(h.t, 3.75f);
    // Across the axis at a's circle of contact (y = -k r0) and at b's (y = L - k r1): on the
    // body's and the cap's common circle, of radius r c.
    ASSERT_TRUE(hit_capsule(make_ray(Vec3(-5, 0, float(-1 - k * 0.5)), Vec3(1, 0, 0)), kA, kB, 0.5f, 0.25f, &h));
    EXPECT_NEAR(h.t, 5.0 - 0.5 * c, 1e-6);
    ASSERT_TRUE(hit_capsule(make_ray(Vec3(-5, 0, float(1 - k * 0.25)), Vec3(1, 0, 0)), kA, kB, 0.5f, 0.25f, &h));
    EXPECT_NEAR(h.t, 5.0 - 0.25 * c, 1e-6);
    // Reversed ends: the same surface.
    ASSERT_TRUE(hit_capsule(make_ray(Vec3(-5, 0, 0), Vec3(1, 0, 0)), kB, kA, 0.25f, 0.5f, &h));
    EXPECT_NEAR(h.t, 5.0 - (0.5 + k * 1.0) / c, 1e-6);
    // From inside: out through the body.
    ASSERT_TRUE(hit_capsule(make_ray(Vec3(0), Vec3(1, 0, 0)), kA, kB, 0.5f, 0.25f, &h));
    EXPECT_NEAR(h.t, (0.5 + k * 1.0) / c, 1e-6);
}

TEST(RayCapsule, TwoRadiiGrazingAndParallelToTheCone) {
    TriangleHit h{};
    const double k = -0.125, c = std::sqrt(1.0 - k * k);
    const float at_middle = float((0.5 + k) / c);  // the body's radius at z = 0
    ASSERT_TRUE(hit_capsule(make_ray(Vec3(-5, std::nextafter(at_middle, 0.0f), 0), Vec3(1, 0, 0)), kA, kB, 0.5f, 0.25f, &h));
    EXPECT_NEAR(h.t, 5.0f, 1e-3f);
    EXPECT_FALSE(hit_capsule(make_ray(Vec3(-5, at_middle * 1.0001f, 0), Vec3(1, 0, 0)), kA, kB, 0.5f, 0.25f, &h));
    // Parallel to one of the cone's lines in the x-z plane (x = (r0 + k y) / c), just outside
    // and just inside it: the quadric's leading term is 0.
    const Vec3 dir(float(k / c), 0, 1);
    const Vec3 on(float(0.5 / c), 0, -1);  // the line at y = 0 (z = -1)
    EXPECT_FALSE(hit_capsule(make_ray(on + Vec3(1e-3f, 0, 0) - 4.0f * dir, dir), kA, kB, 0.5f, 0.25f, &h));
    ASSERT_TRUE(hit_capsule(make_ray(on - Vec3(1e-3f, 0, 0) - 4.0f * dir, dir), kA, kB, 0.5f, 0.25f, &h));
    EXPECT_TRUE(std::isfinite(h.t) && std::isfinite(h.u) && std::isfinite(h.v));
}

TEST(RayCapsule, TwoRadiiOneSphereHoldingTheOtherIsTheLargerSphere) {
    Rng rng(5);
    const Vec3 a(0.1f, 0.2f, 0.3f), b = a + Vec3(0.3f, 0.2f, 0.1f);  // length 0.374 < 1.5 - 0.2
    for (int i = 0; i < 20000; ++i) {
        const Ray r = make_ray(Vec3(6 * rng.next() - 3, 6 * rng.next() - 3, 6 * rng.next() - 3),
                               Vec3(2 * rng.next() - 1, 2 * rng.next() - 1, 2 * rng.next() - 1));
        TriangleHit x{}, y{}, z{};
        const bool cap = hit_capsule(r, a, b, 1.5f, 0.2f, &x), flipped = hit_capsule(r, b, a, 0.2f, 1.5f, &z);
        const bool sph = detail::sphere_kernel(ray_triangle_precompute(r), &a.x, 1.5f, r.tmin, r.tmax, &y);
        ASSERT_EQ(cap, sph) << i;
        ASSERT_EQ(flipped, sph) << i;
        if (cap) EXPECT_FLOAT_EQ(x.t, y.t) << i;
        if (cap) EXPECT_FLOAT_EQ(z.t, y.t) << i;
    }
    TriangleHit h{};  // a tip of radius 0 is a cone's point; a larger radius of 0 is never hit
    EXPECT_TRUE(hit_capsule(make_ray(Vec3(-5, 0, -1), Vec3(1, 0, 0)), kA, kB, 0.5f, 0.0f, &h));
    EXPECT_FALSE(hit_capsule(make_ray(Vec3(-5, 0, 0), Vec3(1, 0, 0)), kA, kB, 0.0f, -1.0f, &h));
}

TEST(RayCapsule, TwoRadiiHugeCoordinatesKeepTheirDigits) {
    TriangleHit h{};
    // At 3e6 floats are 0.25 apart: the ray crosses the axis half-way, at a float.
    const Vec3 a(1e6f, 2e6f, -3e6f), b = a + Vec3(0, 0, 1);
    ASSERT_TRUE(hit_capsule(make_ray(a + Vec3(-10, 0, 0.5f), Vec3(1, 0, 0)), a, b, 1e-2f, 5e-3f, &h));
    const double k = -5e-3, c = std::sqrt(1 - k * k);
    EXPECT_NEAR(h.t, 10.0 - (1e-2 + k * 0.5) / c, 2e-6);
}

TEST(RayCapsule, LeafKernelDispatchesAndCountsCapsules) {
    const HwTriangle rec{{0, 0, -1}, {0, 0, 1}, {0.5f, 0.5f, 0}, 7, 0, kPrimCapsule};
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
