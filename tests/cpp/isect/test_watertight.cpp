// Watertightness on closed meshes: rays from inside a tessellated cube and an icosphere, also
// aimed exactly at shared vertices and edge midpoints, must never escape (Woop et al. 2013 plus
// Ize 2013 in the BVH: both the triangle test and the box test must be robust).
#include <cstdio>

#include <gtest/gtest.h>

#include "isect_test_util.h"
#include "traces/accel/bvh2/bvh2.h"

namespace rtsim {
namespace {

using test::make_ray;

struct EscapeCount {
    long rays = 0;
    long escapes = 0;
};

/// Rays from random interior points (inside the ball of radius `inner`) in random directions.
EscapeCount shoot_random(const HwBvh& bvh, float inner, long n, uint64_t seed) {
    Rng rng(seed);
    EscapeCount c;
    for (long i = 0; i < n; ++i) {
        Vec3 o = test::random_direction(rng) * inner * std::cbrt(rng.next());
        const Hit h = trace_ray(bvh, make_ray(o, test::random_direction(rng)), TraversalMode::closest_hit);
        c.rays += 1;
        c.escapes += h.valid() ? 0 : 1;
    }
    return c;
}

/// Rays aimed at every vertex and every edge midpoint of the soup, from the centre (exactly
/// through them) and from `per_target` random interior origins.
EscapeCount shoot_at_features(const HwBvh& bvh, const std::vector<Vec3>& soup, float inner,
                              int per_target, uint64_t seed) {
    Rng rng(seed);
    std::vector<Vec3> targets;
    for (size_t t = 0; t < soup.size(); t += 3)
        for (int k = 0; k < 3; ++k) {
            targets.push_back(soup[t + k]);
            targets.push_back(0.5f * (soup[t + k] + soup[t + (k + 1) % 3]));
        }
    EscapeCount c;
    for (const Vec3& target : targets) {
        for (int j = 0; j <= per_target; ++j) {
            const Vec3 o = j == 0 ? Vec3(0.0f) : test::random_direction(rng) * inner * rng.next();
            for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
                const Hit h = trace_ray(bvh, make_ray(o, target - o), mode);
                c.rays += 1;
                c.escapes += h.valid() ? 0 : 1;
            }
        }
    }
    return c;
}

void check_closed_mesh(const char* name, const std::vector<Vec3>& soup, float inner) {
    const Scene scene = test::make_scene(soup);
    const HwBvh bvh = test::build(scene);
    const EscapeCount random = shoot_random(bvh, inner, 1000000, 17);
    const EscapeCount aimed = shoot_at_features(bvh, soup, inner, 40, 23);
    std::printf("[ watertight ] %s (%zu triangles): %ld random rays, %ld escapes; %ld rays at "
                "vertices/edge midpoints, %ld escapes\n",
                name, soup.size() / 3, random.rays, random.escapes, aimed.rays, aimed.escapes);
    EXPECT_EQ(random.escapes, 0);
    EXPECT_EQ(aimed.escapes, 0);
}

TEST(Watertight, TessellatedCube) { check_closed_mesh("cube", test::tessellated_cube(8), 0.99f); }

TEST(Watertight, Icosphere) { check_closed_mesh("icosphere", test::icosphere(3), 0.9f); }

TEST(Watertight, CubeAxisRaysThroughEdgesWithSignedZeros) {
    // Axis-parallel rays through grid lines of every face (exactly on shared edges and
    // vertices), with +0 and -0 in the other components.
    const std::vector<Vec3> soup = test::tessellated_cube(4);
    const HwBvh bvh = test::build(test::make_scene(soup));
    long rays = 0, escapes = 0;
    for (int axis = 0; axis < 3; ++axis)
        for (float s : {1.0f, -1.0f})
            for (float z : {0.0f, -0.0f})
                for (int i = 0; i <= 8; ++i)
                    for (int j = 0; j <= 8; ++j) {
                        Vec3 d(z), o(0.0f);
                        d[axis] = s;
                        o[(axis + 1) % 3] = -1.0f + 0.25f * float(i);
                        o[(axis + 2) % 3] = -1.0f + 0.25f * float(j);
                        if (i == 0 || i == 8 || j == 0 || j == 8) continue;  // in the side faces
                        const Hit h = trace_ray(bvh, make_ray(o, d), TraversalMode::closest_hit);
                        rays += 1;
                        escapes += h.valid() ? 0 : 1;
                        if (h.valid()) {
                            EXPECT_EQ(h.t, 1.0f);
                        }
                    }
    EXPECT_EQ(rays, 12 * 49);
    EXPECT_EQ(escapes, 0);
}

}  // namespace
}  // namespace rtsim
