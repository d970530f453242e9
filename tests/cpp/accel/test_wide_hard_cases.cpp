// The numerical hard cases through every wide and compressed BVH, with plain and compressed leaves,
// with no false miss: rays from inside closed meshes (random, and aimed exactly at shared
// vertices and edge midpoints) never escape; axis-parallel rays with signed zeros exactly along
// shared edges hit at t = 1; rays through shared vertices from many origins give the brute-force
// hit bit for bit.
#include <gtest/gtest.h>

#include <cstdio>

#include "accel_test_util.h"
#include "traces/isect/brute_force.h"

namespace rtsim {
namespace {

using test::make_ray;

/// The fused loop's hit, checked against the stepper's (hit bits and every work count): these
/// rays lie in slab planes (0 * inf in the box test) and on shared edges, where a fused loop
/// that folded NaN differently would visit other nodes.
Hit trace(const Accel& accel, const Ray& r, TraversalMode mode) {
    WorkCounts fused_work, step_work;
    const Hit fused = accel.trace(r, mode, &fused_work);
    std::unique_ptr<Stepper> s = accel.make_stepper();
    const Hit stepped = trace_with_stepper(*s, r, mode, &step_work);
    EXPECT_TRUE(test::same_hit(fused, stepped) && fused_work == step_work)
        << accel.kind() << ": fused steps " << fused_work.steps << ", stepper " << step_work.steps;
    bool ran = false;
    WorkCounts sse_work;
    const Hit sse = test::trace_sse2(accel, r, mode, &sse_work, &ran);
    if (ran) {
        EXPECT_TRUE(test::same_hit(sse, stepped) && sse_work == step_work) << accel.kind() << " SSE2";
    }
    return fused;
}

/// Escapes of random interior rays and of rays aimed at every vertex and edge midpoint.
long escapes(const Accel& accel, const std::vector<Vec3>& soup, float inner, int random_rays, uint64_t seed) {
    Rng rng(seed);
    long out = 0;
    for (int i = 0; i < random_rays; ++i) {
        const Vec3 o = test::random_direction(rng) * inner * std::cbrt(rng.next());
        out += !trace(accel, make_ray(o, test::random_direction(rng)), TraversalMode::closest_hit).valid();
    }
    for (size_t t = 0; t < soup.size(); t += 3)
        for (int k = 0; k < 3; ++k)
            for (const Vec3& target : {soup[t + k], 0.5f * (soup[t + k] + soup[t + (k + 1) % 3])})
                for (int j = 0; j < 3; ++j) {
                    const Vec3 o = j == 0 ? Vec3(0.0f) : test::random_direction(rng) * inner * rng.next();
                    for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit})
                        out += !trace(accel, make_ray(o, target - o), mode).valid();
                }
    return out;
}

TEST(WideHardCases, ClosedMeshesNeverLeak) {
    const std::vector<Vec3> cube = test::tessellated_cube(8), sphere = test::icosphere(3);
    const Scene cube_scene = test::make_scene(cube), sphere_scene = test::make_scene(sphere);
    for (const std::string& kind : test::with_compressed_leaves(test::wide_kinds())) {
        const long e = escapes(*test::build_kind(cube_scene, kind, 2), cube, 0.99f, 50000, 17) +
                       escapes(*test::build_kind(sphere_scene, kind, 2), sphere, 0.9f, 50000, 23);
        std::printf("[ watertight ] %s: %ld escapes\n", kind.c_str(), e);
        EXPECT_EQ(e, 0) << kind;
    }
}

TEST(WideHardCases, AxisRaysAlongSharedEdgesWithSignedZeros) {
    const Scene scene = test::make_scene(test::tessellated_cube(4));
    for (const std::string& kind : test::with_compressed_leaves(test::wide_kinds())) {
        const auto accel = test::build_kind(scene, kind, 1);
        int rays = 0, misses = 0;
        for (int axis = 0; axis < 3; ++axis)
            for (float s : {1.0f, -1.0f})
                for (float z : {0.0f, -0.0f})
                    for (int i = 1; i < 8; ++i)
                        for (int j = 1; j < 8; ++j) {
                            Vec3 d(z), o(0.0f);
                            d[axis] = s;
                            o[(axis + 1) % 3] = -1.0f + 0.25f * float(i);
                            o[(axis + 2) % 3] = -1.0f + 0.25f * float(j);
                            for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
                                const Hit h = trace(*accel, make_ray(o, d), mode);
                                ++rays;
                                misses += !h.valid();
                                if (h.valid()) {
                                    EXPECT_EQ(h.t, 1.0f) << kind;
                                }
                            }
                        }
        EXPECT_EQ(rays, 2 * 12 * 49);
        EXPECT_EQ(misses, 0) << kind;
    }
}

TEST(WideHardCases, SharedVerticesFromManyOriginsMatchBruteForce) {
    const std::vector<Vec3> soup = test::tessellated_cube(6);
    const Scene scene = test::make_scene(soup);
    for (const std::string& kind : test::with_compressed_leaves(test::wide_kinds())) {
        const auto accel = test::build_kind(scene, kind, 2);
        const TriangleStore tris = TriangleStore::open(accel->image(), kind);  // plain or decoded
        Rng rng(77);
        int diffs = 0;
        for (size_t k = 0; k < soup.size(); ++k)
            for (int j = 0; j < 3; ++j) {
                const Vec3 o = j == 0 ? Vec3(0.0f) : test::random_point(rng, Vec3(-3), Vec3(3));
                const Ray r = make_ray(o, soup[k] - o);
                const Hit a = trace(*accel, r, TraversalMode::closest_hit);
                const Hit b = trace_ray_brute_force(tris.triangles(), tris.count(), r, TraversalMode::closest_hit);
                diffs += !test::same_hit(a, b);
            }
        EXPECT_EQ(diffs, 0) << kind;
    }
}

}  // namespace
}  // namespace rtsim
