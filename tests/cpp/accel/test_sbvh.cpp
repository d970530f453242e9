// The binary BVH built by SBVH (`--accel bvh2 --builder sbvh`): hits identical to the binned
// tree and to brute force (random soups, every procedural scene, rays along the planes where a
// spatial split cut triangles), the fused loop equal to the stepper, image validation accepting
// a primitive in several triangle records, the manifest's build statistics, and a lower SAH cost
// than binned SAH on the procedural scenes with long, overlapping triangles.
#include <gtest/gtest.h>

#include "structure_test_util.h"
#include "traces/accel/bvh2/bvh2.h"
#include "traces/bvh/builder.h"
#include "traces/bvh/sbvh_config.h"

namespace rtsim {
namespace {

std::unique_ptr<Accel> bvh2_of(const Scene& scene, const std::string& builder) {
    AccelOptions o;
    o.builder = builder;
    return load_accel(build_accel(scene, o), "test " + builder);
}

/// Zero differences against brute force and the binned tree; returns the closest hits.
int expect_same_hits(const Scene& scene, const std::vector<Ray>& rays, const std::string& what) {
    const std::unique_ptr<Accel> sbvh = bvh2_of(scene, "sbvh"), binned = bvh2_of(scene, "binned");
    const std::vector<HwTriangle> tris = test::hw_triangles(scene);
    const test::Agreement a = test::compare_rays(test::tracer(*sbvh), test::tracer(*binned), rays, what + " vs binned");
    EXPECT_EQ(a.diffs, 0) << what;
    if (scene.triangles.size() <= 5000) {
        EXPECT_EQ(test::compare_rays(test::tracer(*sbvh), test::brute_force(tris), rays, what + " vs brute").diffs, 0)
            << what;
    }
    // The fused loop and the stepper: same hits and same work on every ray.
    for (const Ray& r : rays)
        for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
            std::unique_ptr<Stepper> s = sbvh->make_stepper();
            const WorkCounts planned = test::tally_plans(*s, r, mode);
            WorkCounts fused;
            const Hit h = sbvh->trace(r, mode, &fused);
            EXPECT_EQ(planned, s->work());
            EXPECT_EQ(fused, s->work());
            EXPECT_TRUE(test::same_hit(h, s->hit(), TraversalMode::closest_hit));
            if (::testing::Test::HasFailure()) return a.hits;
        }
    return a.hits;
}

TEST(SbvhTrace, HitsEqualBinnedAndBruteForceOnRandomSoups) {
    for (uint64_t seed = 1; seed <= 4; ++seed) {
        const Scene scene = test::random_soup(seed, 300 + 500 * int(seed));
        const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), seed * 13, 4000);
        EXPECT_GT(expect_same_hits(scene, rays, "soup " + std::to_string(seed)), 400);
    }
}

TEST(SbvhTrace, HitsEqualBinnedOnProceduralScenes) {
    for (const std::string& name : procedural_scene_names()) {
        const Scene& scene = test::procedural(name);
        const std::vector<Ray> rays = test::random_rays(scene, test::hw_triangles(scene), 21, 4000);
        EXPECT_GT(expect_same_hits(scene, rays, name), 400) << name;
    }
}

TEST(SbvhTrace, RaysAlongTheSplitPlanes) {
    // A tessellated cube's vertices lie on the planes spatial bins cut at; big diagonal
    // triangles through it get split at the same planes. Rays run along those planes.
    std::vector<Vec3> soup = test::tessellated_cube(4);
    soup.insert(soup.end(), {Vec3(-1, -1, -1), Vec3(1, 1, 1), Vec3(1, -1, 0.5f), Vec3(-1, 1, -1), Vec3(1, -1, 1),
                             Vec3(0, 1, 1)});
    const Scene scene = test::make_scene(soup);
    std::vector<Ray> rays;
    const float coords[] = {-1.0f, -0.5f, 0.0f, 0.5f, 1.0f, 1.5f};
    for (float x : coords)
        for (float y : coords)
            for (const Vec3& d : {Vec3(0, 0, 1), Vec3(0, -0.0f, -1), Vec3(1, 1, 0), Vec3(1, 0, -0.0f)}) {
                rays.push_back(test::make_ray(Vec3(x, y, -3.0f), d));
                rays.push_back(test::make_ray(Vec3(x, -3.0f, y), Vec3(d.y, d.z, d.x)));
                rays.push_back(test::make_ray(Vec3(0.1f * x, 0.2f * y, 0.0f), d));  // from inside
            }
    EXPECT_GT(expect_same_hits(scene, rays, "split planes"), 50);
}

TEST(SbvhImage, DuplicatesAreValidRecordsAndStatsReachTheManifest) {
    const Scene& scene = test::procedural("teapot_stadium");
    const std::unique_ptr<Accel> sbvh = bvh2_of(scene, "sbvh"), binned = bvh2_of(scene, "binned");
    const nlohmann::json& s = sbvh->image().stats;
    EXPECT_EQ(s.at("builder"), "sbvh");
    const uint64_t records = sbvh->image().region("triangles").count;
    EXPECT_EQ(s.at("sbvh").at("references").get<uint64_t>(), records);
    EXPECT_GT(records, scene.triangles.size());
    EXPECT_GT(s.at("sbvh").at("spatial_splits").get<uint64_t>(), 0u);
    EXPECT_EQ(s.at("sbvh").at("config").at("alpha").get<double>(), double(SbvhConfig{}.alpha));
    // Every primitive in at least one record, some in several (validation accepted them).
    std::vector<int> copies(scene.triangles.size(), 0);
    const HwTriangle* t = sbvh->image().region("triangles").records<HwTriangle>();
    for (uint64_t i = 0; i < records; ++i) ++copies[t[i].prim];
    EXPECT_EQ(*std::min_element(copies.begin(), copies.end()), 1);
    EXPECT_GT(*std::max_element(copies.begin(), copies.end()), 1);
    // The flattened tree keeps the SBVH invariants.
    HwBvh bvh;
    const Bvh2View& v = static_cast<const Bvh2Accel&>(*sbvh).view();
    bvh.nodes.assign(v.nodes, v.nodes + v.node_count);
    bvh.triangles.assign(v.triangles, v.triangles + v.triangle_count);
    bvh.bounds = sbvh->image().bounds;
    EXPECT_NO_THROW(check_bvh_invariants(bvh, scene, true));
    // Brute force over the image's records (duplicates included) equals brute force over the scene.
    const std::vector<HwTriangle> tris = test::hw_triangles(scene);
    const std::vector<Ray> rays = test::random_rays(scene, tris, 5, 300);
    const test::Tracer over_records = [&](const Ray& r, TraversalMode m) {
        return trace_ray_brute_force(v.triangles, v.triangle_count, r, m);
    };
    EXPECT_EQ(test::compare_rays(over_records, test::brute_force(tris), rays, "records").diffs, 0);
}

TEST(SbvhImage, LowerSahCostOnProceduralScenes) {
    for (const char* name : {"teapot_stadium", "rotated_walls"}) {
        const Scene& scene = test::procedural(name);
        const double binned = bvh2_of(scene, "binned")->image().stats.at("sah_cost");
        const double sbvh = bvh2_of(scene, "sbvh")->image().stats.at("sah_cost");
        std::printf("[ sbvh ] %s: SAH binned %.2f, sbvh %.2f (%.3fx)\n", name, binned, sbvh, sbvh / binned);
        EXPECT_LT(sbvh, binned) << name;
    }
}

}  // namespace
}  // namespace rtsim
