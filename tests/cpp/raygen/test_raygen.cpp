// Ray generation: robust origins (no self-hits), the workload plan, determinism of sampling.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>

#include "traces/bvh/builder.h"
#include "traces/accel/bvh2/bvh2.h"
#include "traces/common/rng.h"
#include "traces/raygen/camera.h"
#include "traces/raygen/secondary.h"
#include "traces/raygen/surface.h"
#include "traces/scene/gltf_loader.h"
#include "traces/scene/procedural.h"
#include "tests/cpp/process_temp_dir.h"

namespace fs = std::filesystem;
using namespace rtsim;

namespace {

Scene procedural(const std::string& name) {
    const fs::path dir = test::process_temp_dir("raygen");
    ProceduralOptions o;
    o.hairball_triangles = 20000;
    return load_gltf(write_procedural_scene(name, dir.string(), o));
}

const std::vector<RayKind> kAll = {RayKind::primary, RayKind::shadow, RayKind::reflection, RayKind::diffuse,
                                   RayKind::refraction};

/// Primary hits of a 64x48 view from the scene's camera.
std::vector<std::pair<PendingRay, Hit>> primary_hits(const Scene& scene, const HwBvh& bvh) {
    PinholeCamera cam = make_camera(scene.cameras.at(0), 64, 48);
    std::vector<std::pair<PendingRay, Hit>> out;
    for (uint32_t y = 0; y < 48; ++y)
        for (uint32_t x = 0; x < 64; ++x) {
            PendingRay r;
            r.ray = primary_ray(cam, x, y, 64, 48);
            r.pixel = y * 64 + x;
            Hit h = trace_ray(bvh, r.ray, TraversalMode::closest_hit);
            if (h.valid()) out.emplace_back(r, h);
        }
    return out;
}

}  // namespace

TEST(RayGen, SecondaryRaysNeverRehitTheirOwnTriangle) {
    // A flat triangle cannot be hit again by a ray leaving it; any such hit is a self-hit from a
    // bad origin offset. Covers walls in the planes x = 0 and y = 0 (Cornell box), tilted walls,
    // and the tiny teapot inside the huge stadium.
    for (const std::string& name : procedural_scene_names()) {
        SCOPED_TRACE(name);
        Scene scene = procedural(name);
        HwBvh bvh = build_bvh(scene);
        WorkloadPlan plan = plan_workload(scene, kAll);
        SpawnContext ctx{&scene, &plan, 4, 7};
        uint64_t secondaries = 0, self_hits = 0;
        uint64_t index = 0;
        for (const auto& [parent, hit] : primary_hits(scene, bvh)) {
            std::vector<PendingRay> rays;
            spawn_secondaries(ctx, parent, hit, index++, &rays);
            for (const PendingRay& r : rays) {
                Hit h = trace_ray(bvh, r.ray, TraversalMode::closest_hit);
                ++secondaries;
                self_hits += h.valid() && h.prim == hit.prim;
            }
        }
        EXPECT_GT(secondaries, 300u);
        EXPECT_EQ(self_hits, 0u);
    }
}

TEST(RayGen, OffsetOriginLeavesTheSurfaceAtEveryScale) {
    // The same triangle at 1e-6, 1 and 1e6 scale, and lying in the plane x = 0 where pbrt's error
    // bound alone is zero: the offset origin is strictly on the side the ray leaves to.
    for (float s : {1e-6f, 1.0f, 1e6f}) {
        Scene scene;
        Mesh mesh;
        mesh.positions = {Vec3(0, -1, -1) * s, Vec3(0, 1, -1) * s, Vec3(0, 0, 1) * s};
        mesh.materials = {scene.default_material()};
        scene.meshes.push_back(mesh);
        scene.instances.push_back(Instance{});
        scene.flatten();
        Ray in{Vec3(-1, 0.1f, 0.2f) * s, 0.0f, Vec3(1, 0, 0), INFINITY};
        Hit h;
        h.prim = 0;
        h.t = s;
        h.u = 0.3f;
        h.v = 0.3f;
        SurfacePoint sp = surface_point(scene, in, h);
        Vec3 back = offset_ray_origin(sp, Vec3(-1, 0, 0));
        Vec3 through = offset_ray_origin(sp, Vec3(1, 0, 0));
        EXPECT_LT(back.x, 0.0f) << s;
        EXPECT_GT(through.x, 0.0f) << s;
    }
}

TEST(RayGen, SpawningDependsOnlyOnTheParent) {
    // Secondaries of a parent are the same bits whatever order parents are processed in (what
    // makes traces independent of the thread count), and change with the seed.
    Scene scene = procedural("cornell");
    HwBvh bvh = build_bvh(scene);
    WorkloadPlan plan = plan_workload(scene, kAll);
    SpawnContext ctx{&scene, &plan, 2, 99};
    auto hits = primary_hits(scene, bvh);
    std::vector<std::vector<PendingRay>> forward(hits.size()), backward(hits.size());
    for (size_t i = 0; i < hits.size(); ++i) spawn_secondaries(ctx, hits[i].first, hits[i].second, i, &forward[i]);
    for (size_t i = hits.size(); i-- > 0;) spawn_secondaries(ctx, hits[i].first, hits[i].second, i, &backward[i]);
    SpawnContext other = ctx;
    other.seed = 100;
    size_t differing = 0, diffuse = 0;
    for (size_t i = 0; i < hits.size(); ++i) {
        ASSERT_EQ(forward[i].size(), backward[i].size());
        for (size_t k = 0; k < forward[i].size(); ++k)
            ASSERT_EQ(std::memcmp(&forward[i][k].ray, &backward[i][k].ray, sizeof(Ray)), 0);
        std::vector<PendingRay> reseeded;
        spawn_secondaries(other, hits[i].first, hits[i].second, i, &reseeded);
        for (size_t k = 0; k < reseeded.size() && k < forward[i].size(); ++k)
            if (reseeded[k].kind == RayKind::diffuse) {
                ++diffuse;
                differing += std::memcmp(&reseeded[k].ray, &forward[i][k].ray, sizeof(Ray)) != 0;
            }
    }
    EXPECT_GT(diffuse, 100u);
    EXPECT_GT(differing, diffuse * 9 / 10);
}

TEST(RayGen, PlanFollowsTheScene) {
    Scene cornell = procedural("cornell");
    WorkloadPlan plan = plan_workload(cornell, kAll);
    EXPECT_TRUE(plan.wants(RayKind::shadow));      // emissive ceiling light
    EXPECT_TRUE(plan.wants(RayKind::reflection));  // mirror box
    EXPECT_FALSE(plan.wants(RayKind::refraction));
    EXPECT_FALSE(plan.emissive_prims.empty());
    WorkloadPlan only_primary = plan_workload(cornell, {RayKind::primary});
    EXPECT_FALSE(only_primary.wants(RayKind::shadow));
    for (const Effect& e : only_primary.effects) {
        if (e.name == "shadow") {
            EXPECT_NE(e.why.find("not requested"), std::string::npos);
        }
    }
}

TEST(RayGen, EmptyRequestIsWhatTheSceneCallsFor) {
    Scene cornell = procedural("cornell");
    WorkloadPlan by_default = plan_workload(cornell, {});
    WorkloadPlan everything = plan_workload(cornell, kAll);
    for (int k = 0; k < kRayKindCount; ++k) EXPECT_EQ(by_default.wants(RayKind(k)), everything.wants(RayKind(k)));
    EXPECT_TRUE(by_default.wants(RayKind::primary) && by_default.wants(RayKind::diffuse));
    EXPECT_FALSE(by_default.wants(RayKind::refraction));
    for (const Effect& e : by_default.effects) {
        // Nobody asked: kinds the scene does not call for say why, not "requested, but".
        if (e.name == "refraction") {
            EXPECT_EQ(e.why, "no material has KHR_materials_transmission");
        }
        if (e.name == "shadow") {
            EXPECT_TRUE(e.simulated);
        }
    }
}

TEST(RayGen, GlossyReflectionsFollowTheGgxLobe) {
    // At normal incidence the visible-normal distribution is the GGX normal distribution times
    // cos(theta_h), whose tan^2(theta_h) has the CDF x / (alpha^2 + x): half the samples' half
    // vectors lie within tan^2 = alpha^2, and the reflection stays above the surface when
    // theta_h is below 45 degrees (tan^2 <= 1), for 1 / (1 + alpha^2) of them.
    const Vec3 n(0.0f, 0.0f, 1.0f), down(0.0f, 0.0f, -1.0f);
    for (float alpha : {0.05f, 0.3f, 0.8f}) {
        Rng rng(5);
        const int total = 20000;
        int inside = 0, above = 0;
        for (int i = 0; i < total; ++i) {
            Vec3 out;
            const float u1 = rng.next(), u2 = rng.next();
            const bool up = ggx_reflect(down, n, alpha, u1, u2, &out);
            ASSERT_NEAR(glm::length(out), 1.0f, 1e-5f);
            ASSERT_EQ(up, out.z > 0.0f);
            const Vec3 h = glm::normalize(out - down);  // the sampled microfacet normal
            const float tan2 = (1.0f - h.z * h.z) / (h.z * h.z);
            inside += tan2 <= alpha * alpha;
            above += up;
        }
        EXPECT_NEAR(double(inside) / total, 0.5, 0.02) << alpha;
        EXPECT_NEAR(double(above) / total, 1.0 / (1.0 + alpha * alpha), 0.02) << alpha;
    }
    // At 60 degrees the lobe widens with roughness around the mirror direction.
    const Vec3 d = glm::normalize(Vec3(std::sin(1.047f), 0.0f, -std::cos(1.047f)));
    const Vec3 mirror = reflect(d, n);
    double previous = 1.0;
    for (float alpha : {0.01f, 0.1f, 0.4f}) {
        Rng rng(6);
        double sum = 0;
        int kept = 0;
        for (int i = 0; i < 5000; ++i) {
            Vec3 out;
            const float u1 = rng.next(), u2 = rng.next();
            if (ggx_reflect(d, n, alpha, u1, u2, &out)) sum += glm::dot(out, mirror), ++kept;
        }
        const double mean = sum / kept;
        if (alpha == 0.01f) EXPECT_GT(mean, 0.999);
        EXPECT_LT(mean, previous) << alpha;
        previous = mean;
    }
}

TEST(RayGen, RussianRouletteKeepsPathsWithTheSurfacesAlbedo) {
    Scene scene = procedural("cornell");
    HwBvh bvh = build_bvh(scene);
    WorkloadPlan plan = plan_workload(scene, {RayKind::primary, RayKind::diffuse});
    SpawnContext plain{&scene, &plan, 8, 3};
    SpawnContext roulette = plain;
    roulette.roulette_after = 2;
    size_t all = 0, kept = 0;
    double expected = 0;
    for (auto [parent, hit] : primary_hits(scene, bvh)) {
        std::vector<PendingRay> before, after, again;
        parent.depth = 1;  // below roulette_after: every path goes on
        spawn_secondaries(roulette, parent, hit, 0, &before);
        EXPECT_EQ(before.size(), 1u);
        parent.depth = 2;  // past it: kept with the albedo's probability
        spawn_secondaries(plain, parent, hit, 0, &after);
        spawn_secondaries(roulette, parent, hit, 0, &again);
        std::vector<PendingRay> repeat;
        spawn_secondaries(roulette, parent, hit, 0, &repeat);
        ASSERT_EQ(again.size(), repeat.size());  // deterministic for the seed
        all += after.size(), kept += again.size();
        expected += roulette_survival(scene.materials[surface_point(scene, parent.ray, hit).material]);
        if (!again.empty()) EXPECT_EQ(std::memcmp(&again[0].ray, &after[0].ray, sizeof(Ray)), 0);
    }
    ASSERT_GT(all, 2000u);
    EXPECT_NEAR(double(kept), expected, 0.05 * expected);
    EXPECT_LT(kept, all);
}
