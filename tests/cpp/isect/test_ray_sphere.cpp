// Ray/sphere test (Haines et al. 2019, ray_sphere_kernel.h): the nearer crossing, rays from
// inside and from the surface, tangent and grazing rays, huge and tiny coordinates, small
// distant spheres, degenerate radii, and spheres mixed with triangles in a BVH against brute force.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "isect_test_util.h"
#include "traces/accel/accel.h"
#include "traces/bvh/build_tree.h"
#include "traces/bvh/builder.h"
#include "traces/common/error.h"
#include "traces/common/rng.h"
#include "traces/isect/brute_force.h"
#include "traces/isect/leaf_kernel.h"
#include "traces/raygen/workload.h"

namespace rtsim {
namespace {

using test::make_ray;

bool hit_sphere(const Ray& r, const Vec3& c, float radius, TriangleHit* h) {
    return detail::sphere_kernel(ray_triangle_precompute(r), &c.x, radius, r.tmin, r.tmax, h);
}

TEST(RaySphere, NearerCrossingFarOneFromInsideNoneBehind) {
    TriangleHit h{};
    ASSERT_TRUE(hit_sphere(make_ray(Vec3(0, 0, -5), Vec3(0, 0, 1)), Vec3(0), 1.0f, &h));
    EXPECT_FLOAT_EQ(h.t, 4.0f);
    EXPECT_FLOAT_EQ(h.v, 1.0f);  // the hit is the south pole (normal -z): colatitude pi
    // From inside: the far crossing.
    ASSERT_TRUE(hit_sphere(make_ray(Vec3(0), Vec3(0, 0, 1)), Vec3(0), 1.0f, &h));
    EXPECT_FLOAT_EQ(h.t, 1.0f);
    // Behind the ray, and beside it.
    EXPECT_FALSE(hit_sphere(make_ray(Vec3(0, 0, 5), Vec3(0, 0, 1)), Vec3(0), 1.0f, &h));
    EXPECT_FALSE(hit_sphere(make_ray(Vec3(2, 0, -5), Vec3(0, 0, 1)), Vec3(0), 1.0f, &h));
    // An unnormalised direction: t in units of its length.
    ASSERT_TRUE(hit_sphere(make_ray(Vec3(0, 0, -5), Vec3(0, 0, 1000)), Vec3(0), 1.0f, &h));
    EXPECT_FLOAT_EQ(h.t, 0.004f);
    // The interval: tmax excludes a crossing beyond it, then the far one is tried.
    EXPECT_FALSE(hit_sphere(make_ray(Vec3(0, 0, -5), Vec3(0, 0, 1), 0.0f, 3.9f), Vec3(0), 1.0f, &h));
    ASSERT_TRUE(hit_sphere(make_ray(Vec3(0, 0, -5), Vec3(0, 0, 1), 4.5f, 10.0f), Vec3(0), 1.0f, &h));
    EXPECT_FLOAT_EQ(h.t, 6.0f);
}

TEST(RaySphere, RayFromTheSurfaceMissesItselfAtTmin) {
    // Spawned at the surface (tmin = 0 excluded): outward misses, inward crosses the far side.
    TriangleHit h{};
    EXPECT_FALSE(hit_sphere(make_ray(Vec3(0, 0, 1), Vec3(0, 0, 1)), Vec3(0), 1.0f, &h));
    ASSERT_TRUE(hit_sphere(make_ray(Vec3(0, 0, 1), Vec3(0, 0, -1)), Vec3(0), 1.0f, &h));
    EXPECT_FLOAT_EQ(h.t, 2.0f);
}

TEST(RaySphere, TangentRaysTouchAndGrazingRaysDecideBySide) {
    TriangleHit h{};
    // Exactly tangent (the discriminant is exactly zero): one point of contact.
    ASSERT_TRUE(hit_sphere(make_ray(Vec3(1, 0, -5), Vec3(0, 0, 1)), Vec3(0), 1.0f, &h));
    EXPECT_FLOAT_EQ(h.t, 5.0f);
    EXPECT_FALSE(hit_sphere(make_ray(Vec3(1.0f + 1e-6f, 0, -5), Vec3(0, 0, 1)), Vec3(0), 1.0f, &h));
    ASSERT_TRUE(hit_sphere(make_ray(Vec3(1.0f - 1e-6f, 0, -5), Vec3(0, 0, 1)), Vec3(0), 1.0f, &h));
    EXPECT_NEAR(h.t, 5.0f, 2e-3f);
    // Diagonal and axis-parallel grazing rays: never NaN, hit or miss consistently by side.
    for (int axis = 0; axis < 3; ++axis) {
        Vec3 o(0.0f), d(0.0f);
        o[axis] = -10.0f;
        d[axis] = 1.0f;
        o[(axis + 1) % 3] = std::nextafter(1.0f, 0.0f);
        ASSERT_TRUE(hit_sphere(make_ray(o, d), Vec3(0), 1.0f, &h)) << axis;
        EXPECT_TRUE(std::isfinite(h.t) && std::isfinite(h.u) && std::isfinite(h.v)) << axis;
        o[(axis + 1) % 3] = std::nextafter(1.0f, 2.0f);
        EXPECT_FALSE(hit_sphere(make_ray(o, d), Vec3(0), 1.0f, &h)) << axis;
    }
}

TEST(RaySphere, HugeAndTinyCoordinatesKeepTheirDigits) {
    TriangleHit h{};
    // A millimetre sphere a million units from the origin, seen from 10 units away.
    const Vec3 c(1e6f, -2e6f, 3e6f);
    ASSERT_TRUE(hit_sphere(make_ray(c - Vec3(10, 0, 0), Vec3(1, 0, 0)), c, 1e-3f, &h));
    EXPECT_NEAR(h.t, 10.0f - 1e-3f, 1e-5f);
    // A small sphere far down the ray (the textbook formula loses it to cancellation).
    ASSERT_TRUE(hit_sphere(make_ray(Vec3(0), Vec3(0, 0, 1)), Vec3(0, 0, 1e5f), 1e-2f, &h));
    EXPECT_NEAR(h.t, 1e5f - 1e-2f, 1e-2f);
    ASSERT_TRUE(hit_sphere(make_ray(Vec3(0), Vec3(1, 1, 1)), Vec3(1e4f, 1e4f, 1e4f), 1e-3f, &h));
    EXPECT_NEAR(h.t, 1e4f, 1e-2f);
    // Tiny: radius 1e-25 at 1e-20 (squares far below float's range, fine in double).
    ASSERT_TRUE(hit_sphere(make_ray(Vec3(0), Vec3(1, 0, 0)), Vec3(1e-20f, 0, 0), 1e-25f, &h));
    EXPECT_NEAR(h.t / 1e-20f, 1.0f, 1e-4f);
    // Huge: radius 1e30 (its square overflows float, not double).
    ASSERT_TRUE(hit_sphere(make_ray(Vec3(0, 0, -3e30f), Vec3(0, 0, 1)), Vec3(0), 1e30f, &h));
    EXPECT_FLOAT_EQ(h.t, 2e30f);
}

TEST(RaySphere, DegenerateRadiiAreNeverHit) {
    TriangleHit h{};
    for (float r : {0.0f, -1.0f, std::nanf(""), INFINITY})
        EXPECT_FALSE(hit_sphere(make_ray(Vec3(0, 0, -5), Vec3(0, 0, 1)), Vec3(0), r, &h)) << r;
}

TEST(RaySphere, AgreesWithLongDoubleOnRandomRays) {
    // Random rays at a unit sphere: hit/miss agrees with the exact answer (long double) except
    // within a relative 1e-6 of tangency, and t to a relative 1e-6.
    Rng rng(7);
    int checked = 0;
    for (int i = 0; i < 100000; ++i) {
        const Vec3 o(8 * rng.next() - 4, 8 * rng.next() - 4, 8 * rng.next() - 4);
        const Vec3 d(2 * rng.next() - 1, 2 * rng.next() - 1, 2 * rng.next() - 1);
        if (glm::length(d) < 1e-3f) continue;
        const long double ox = o.x, oy = o.y, oz = o.z, dx = d.x, dy = d.y, dz = d.z;
        const long double a = dx * dx + dy * dy + dz * dz, b = ox * dx + oy * dy + oz * dz,
                          c = ox * ox + oy * oy + oz * oz - 1.0L, disc = b * b - a * c;
        if (std::fabs(double(disc)) < 1e-6 * double(a)) continue;
        ++checked;
        long double t = disc < 0 ? -1 : (-b - std::sqrt(disc)) / a;
        if (disc >= 0 && t <= 0) t = (-b + std::sqrt(disc)) / a;
        TriangleHit h{};
        const bool got = hit_sphere(make_ray(o, d), Vec3(0), 1.0f, &h);
        ASSERT_EQ(got, disc >= 0 && t > 0) << i;
        if (got) {
            EXPECT_NEAR(h.t, double(t), 1e-6 * std::max(1.0, double(t))) << i;
        }
    }
    EXPECT_GT(checked, 90000);
}

/// A scene of spheres and triangles: an icosphere, 300 random spheres, a floor.
Scene mixed_scene() {
    Scene scene;
    Mesh mesh;
    mesh.name = "mixed";
    mesh.positions = test::icosphere(2);
    for (Vec3& p : mesh.positions) p = 0.5f * p;
    mesh.positions.insert(mesh.positions.end(), {{-3, -1, -3}, {3, -1, -3}, {3, -1, 3}, {-3, -1, -3}, {3, -1, 3}, {-3, -1, 3}});
    const size_t triangles = mesh.positions.size() / 3;
    mesh.radii.assign(triangles, 0.0f);
    Rng rng(3);
    for (int i = 0; i < 300; ++i) {
        const Vec3 c(4 * rng.next() - 2, 2 * rng.next() - 1, 4 * rng.next() - 2);
        mesh.positions.insert(mesh.positions.end(), {c, c, c});
        mesh.radii.push_back(0.02f + 0.2f * rng.next());
    }
    for (int i = 0; i < 100; ++i) {  // capsules: two ends and the second again
        const Vec3 a(4 * rng.next() - 2, 2 * rng.next() - 1, 4 * rng.next() - 2);
        const Vec3 b = a + 0.5f * Vec3(rng.next() - 0.5f, rng.next() - 0.5f, rng.next() - 0.5f);
        mesh.positions.insert(mesh.positions.end(), {a, b, b});
        mesh.radii.push_back(0.01f + 0.05f * rng.next());
    }
    mesh.materials.assign(mesh.positions.size() / 3, 0u);
    scene.meshes.push_back(mesh);
    scene.instances.push_back(Instance{});
    scene.materials = {Material{}};
    scene.flatten();
    return scene;
}

TEST(RaySphere, SpheresFlattenToTheirBoxAndCentre) {
    const Scene scene = mixed_scene();
    ASSERT_EQ(scene.sphere_count(), 300u);
    ASSERT_EQ(scene.capsule_count(), 100u);
    for (uint32_t p = 0; p < scene.triangles.size(); ++p) {
        if (!scene.is_curved(p)) continue;
        const Triangle& t = scene.triangles[p];
        const float r = scene.curved_radius[p];
        const Vec3 a = scene.is_capsule(p) ? scene.capsule_ends[p][0] : t.v2;
        const Vec3 b = scene.is_capsule(p) ? scene.capsule_ends[p][1] : t.v2;
        for (int k = 0; k < 3; ++k) {
            EXPECT_LE(double(t.v0[k]), double(std::min(a[k], b[k])) - double(r)) << p;
            EXPECT_GE(double(t.v1[k]), double(std::max(a[k], b[k])) + double(r)) << p;
        }
        if (scene.is_capsule(p)) {
            const HwTriangle rec = make_hw_triangle(scene, p);
            EXPECT_TRUE(is_capsule(rec) && rec.v2[0] == r && rec.v0[0] == a.x && rec.v1[2] == b.z) << p;
        }
    }
}

TEST(RaySphere, EachSphereKeepsItsOwnRadiusAndTheNodeScalesIt) {
    // Spheres first (no triangle before them), then a triangle, under a scale of 2.
    Scene scene;
    Mesh mesh;
    mesh.name = "beads";
    mesh.positions = {Vec3(0), Vec3(0), Vec3(0), Vec3(5, 0, 0), Vec3(5, 0, 0), Vec3(5, 0, 0),
                      Vec3(0, 3, 0), Vec3(1, 3, 0), Vec3(0, 4, 0)};
    mesh.radii = {1.0f, 0.5f, 0.0f};
    mesh.materials = {0, 0, 0};
    scene.meshes.push_back(mesh);
    Instance inst;
    inst.object_to_world = glm::dmat4(2.0);
    inst.object_to_world[3][3] = 1.0;
    scene.instances.push_back(inst);
    scene.materials = {Material{}};
    scene.flatten();
    ASSERT_EQ(scene.curved_radius.size(), 3u);
    EXPECT_EQ(scene.curved_radius[0], 2.0f);
    EXPECT_EQ(scene.curved_radius[1], 1.0f);
    EXPECT_FALSE(scene.is_sphere(2));
    EXPECT_EQ(make_hw_triangle(scene, 1).v1[0], 1.0f);
    EXPECT_EQ(make_hw_triangle(scene, 1).v0[0], 10.0f);
    const HwBvh bvh = build_bvh(scene);
    const Hit h = trace_ray_brute_force(bvh.triangles.data(), bvh.triangles.size(),
                                        make_ray(Vec3(10, 0, -5), Vec3(0, 0, 1)), TraversalMode::closest_hit);
    EXPECT_EQ(h.prim, 1);
    EXPECT_FLOAT_EQ(h.t, 4.0f);
}

TEST(RaySphere, ANodeScaledToZeroHidesItsSpheres) {
    // glTF hides nodes by scaling them to 0: the sphere is flattened with radius 0, never hit.
    Scene scene;
    Mesh mesh;
    mesh.name = "hidden";
    mesh.positions = {Vec3(0), Vec3(0), Vec3(0)};
    mesh.radii = {1.0f};
    mesh.materials = {0};
    scene.meshes.push_back(mesh);
    Instance inst;
    inst.object_to_world = glm::dmat4(0.0);
    inst.object_to_world[3][3] = 1.0;
    scene.instances.push_back(inst);
    scene.materials = {Material{}};
    scene.flatten();
    EXPECT_FALSE(scene.is_sphere(0));
    const HwBvh bvh = build_bvh(scene);
    EXPECT_FALSE(trace_ray_brute_force(bvh.triangles.data(), bvh.triangles.size(),
                                       make_ray(Vec3(0, 0, -5), Vec3(0, 0, 1)), TraversalMode::closest_hit)
                     .valid());
}

TEST(RaySphere, AnAlphaMaskedSphereShowsItsFarSideWhereItsNearSideIsCutOut) {
    // One MASK sphere (coverage 0.5): a ray whose near crossing fails the alpha test goes on
    // to the far crossing, which has an alpha test of its own.
    HwTriangle rec{{0, 0, 0}, {1, 0, 0}, {0, 0, 0}, 0, 0, kPrimSphere | kTriAnyHit | (128u << kTriCoverageShift)};
    Rng rng(5);
    int near = 0, far = 0, none = 0;
    for (int i = 0; i < 2000; ++i) {
        const float x = 0.9f * (2 * rng.next() - 1), y = 0.9f * (2 * rng.next() - 1);
        if (x * x + y * y > 0.81f) continue;  // every ray crosses the sphere twice
        const Ray r = make_ray(Vec3(x, y, -5), Vec3(0, 0, 1));
        Hit best;
        best.t = r.tmax;
        float cull = detail::cull_distance(best.t);
        uint32_t alpha = 0;
        const bool hit = detail::triangle_step<false>(ray_triangle_precompute(r), r.tmin, r.tmax, rec, best, cull, alpha);
        if (!hit) {
            EXPECT_EQ(alpha, 2u);
            ++none;
        } else if (best.t < 5.0f) {
            EXPECT_EQ(alpha, 1u);
            ++near;
        } else {
            EXPECT_EQ(alpha, 2u);  // the near side was cut out here
            ++far;
        }
    }
    EXPECT_GT(near, 500);
    EXPECT_GT(far, 200);
    EXPECT_GT(none, 200);
}

TEST(RaySphere, EmissiveSpheresAndCapsulesAreAreaLightsSampledOnTheirSurface) {
    for (bool capsule : {false, true}) {
        Scene scene = mixed_scene();
        Material glow;
        glow.emissive = Vec3(4.0f);
        scene.materials.push_back(glow);
        uint32_t lamp = 0;
        for (uint32_t p = 0; p < scene.triangles.size(); ++p)
            if (capsule ? scene.is_capsule(p) : scene.is_sphere(p)) lamp = p;
        scene.meshes[0].materials[lamp] = 1;
        scene.flatten();
        const WorkloadPlan plan = plan_workload(scene, {RayKind::primary, RayKind::shadow});
        ASSERT_EQ(plan.emissive_prims, std::vector<uint32_t>{lamp});
        const glm::dvec3 a(capsule ? scene.capsule_ends[lamp][0] : sphere_centre(scene.triangles[lamp]));
        const glm::dvec3 b(capsule ? scene.capsule_ends[lamp][1] : sphere_centre(scene.triangles[lamp]));
        for (float u : {0.05f, 0.3f, 0.5f, 0.7f, 0.95f}) {
            const std::vector<LightSample> s = light_samples(scene, plan, 0.5f, u, 1.0f - u);
            ASSERT_EQ(s.size(), 1u);
            const glm::dvec3 p(s[0].point);
            const double t = capsule ? glm::clamp(glm::dot(p - a, b - a) / glm::dot(b - a, b - a), 0.0, 1.0) : 0.0;
            EXPECT_NEAR(glm::length(p - (a + t * (b - a))), scene.curved_radius[lamp], 1e-5) << capsule << " " << u;
        }
    }
}

TEST(RaySphere, BvhOverSpheresAndTrianglesMatchesBruteForce) {
    const Scene scene = mixed_scene();
    for (const char* kind : {"bvh2", "bvh4", "bvh8", "cwbvh8", "bih", "bkd", "obvh2"}) {
        AccelOptions o;
        o.kind = kind;
        const std::unique_ptr<Accel> accel = load_accel(build_accel(scene, o), kind);
        ASSERT_TRUE(accel->has_spheres() && accel->has_capsules());
        const HwBvh flat = build_bvh(scene);
        check_bvh_invariants(flat, scene);
        Rng rng(11);
        uint64_t sphere_hits = 0, sphere_tests = 0, capsule_hits = 0, capsule_tests = 0;
        for (int i = 0; i < 4000; ++i) {
            const Vec3 o(0, 0.5f, 6), target(4 * rng.next() - 2, 2.5f * rng.next() - 1.2f, 4 * rng.next() - 2);
            const Ray r = make_ray(o, target - o);
            for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
                WorkCounts w;
                const Hit got = accel->trace(r, mode, &w);
                const Hit want = trace_ray_brute_force(flat.triangles.data(), flat.triangles.size(), r, mode);
                ASSERT_EQ(got.valid(), want.valid()) << kind << " ray " << i;
                if (mode == TraversalMode::closest_hit && want.valid()) {
                    EXPECT_EQ(got.prim, want.prim) << kind << " ray " << i;
                    EXPECT_EQ(got.t, want.t) << kind << " ray " << i;
                    sphere_hits += scene.is_sphere(uint32_t(got.prim));
                    capsule_hits += scene.is_capsule(uint32_t(got.prim));
                }
                // The stepper (what the model drives) counts what the fused loop counts.
                WorkCounts stepped;
                StepOptions walk;
                walk.anyhit_order = AnyHitOrder::nearest;
                const std::unique_ptr<Stepper> s = accel->make_stepper(walk);
                const Hit again = trace_with_stepper(*s, r, mode, &stepped);
                EXPECT_EQ(again.prim, got.prim) << kind;
                EXPECT_EQ(stepped, w) << kind << " ray " << i;
                sphere_tests += w.sphere_tests;
                capsule_tests += w.capsule_tests;
            }
        }
        EXPECT_GT(sphere_hits, 400u) << kind;
        EXPECT_GT(sphere_tests, 0u) << kind;
        EXPECT_GT(capsule_hits, 20u) << kind;
        EXPECT_GT(capsule_tests, 0u) << kind;
    }
}

TEST(RaySphere, StructuresThatClipRefuseSpheres) {
    const Scene scene = mixed_scene();
    for (const char* kind : {"kdtree", "grid", "octree", "gkbvh"}) {
        AccelOptions o;
        o.kind = kind;
        try {
            build_accel(scene, o);
            FAIL() << kind << " accepted spheres";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("the scene has curved primitives"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("bvh2"), std::string::npos) << e.what();
        }
    }
    AccelOptions sbvh;
    sbvh.builder = "sbvh";
    EXPECT_THROW(build_accel(scene, sbvh), Error);
}

}  // namespace
}  // namespace rtsim
