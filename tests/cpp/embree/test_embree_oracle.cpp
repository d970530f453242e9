// rtsim's trace_ray against Embree 3 (robust mode, one thread, high-quality build) on Sponza, the
// hairball (thin triangles: many edge cases) and the Cornell box: primary rays from the
// automatic framing camera, one diffuse bounce from their hits, and shadow-like any-hit rays to a
// point light. Alpha MASK triangles are tested through an Embree filter function running the
// same alpha_test_accepts on Embree's own u, v (embree_oracle.h). Criteria (docs/validation.md):
// hit/miss agreement >= 99.99%, every disagreement explained by an edge, vertex, tie, alpha
// boundary or interval end (oracle_compare.h), t within 1e-4 relative where both hit one prim.
#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "embree_oracle.h"
#include "oracle_compare.h"
#include "oracle_rays.h"
#include "traces/bvh/builder.h"
#include "tests/cpp/process_temp_dir.h"

namespace rtsim::oracle {
namespace {


std::string sponza_path() {
    const char* env = std::getenv("RTSIM_SCENES");
    const std::string dir = env && *env ? env : RTSIM_SCENES_DIR;
    return (std::filesystem::path(dir) / "sponza" / "Sponza.gltf").string();
}

void check(const std::string& name, const char* kind, const Tally& t) {
    print_tally(name, kind, t);
    EXPECT_GT(t.rays, 0u) << name << " " << kind;
    EXPECT_GE(t.hit_miss_agreement(), 0.9999) << name << " " << kind;
    EXPECT_EQ(t.unexplained(), 0u) << name << " " << kind << ": disagreements not at an edge";
    EXPECT_EQ(t.t_out_of_tol, 0u) << name << " " << kind << ": t differs by more than 1e-4";
}

/// The three comparisons on one scene, with width x height primary rays.
void compare_scene(const std::string& name, const Scene& scene, uint32_t width = 320, uint32_t height = 240) {
    const HwBvh bvh = build_bvh(scene);
    const EmbreeScene embree(scene, EmbreeScene::Options{});
    const RaySets sets = make_ray_sets(scene, bvh, width, height);
    std::printf("[ embree    ] %s: %zu triangles, camera: %s, light (%g, %g, %g)\n", name.c_str(),
                scene.triangle_count(), sets.camera_why.c_str(), sets.light.x, sets.light.y, sets.light.z);
    const Comparer cmp(bvh, embree);
    Tally primary, diffuse, shadow;
    for (const Ray& r : sets.primary) cmp.closest(r, &primary);
    for (const Ray& r : sets.diffuse) cmp.closest(r, &diffuse);
    for (const Ray& r : sets.shadow) cmp.any(r, &shadow);
    check(name, "primary", primary);
    check(name, "diffuse", diffuse);
    check(name, "shadow", shadow);
    // The ray sets must exercise something (the hairball is sparse: about 12% of its view hits).
    EXPECT_GT(primary.rtsim_hits, primary.rays / 20) << name;
    EXPECT_GT(shadow.rtsim_hits, 0u) << name;
}

std::string scratch_dir() {
    return rtsim::test::process_temp_dir("embree_oracle").string();
}

TEST(EmbreeOracle, Sponza) {
    const std::string path = sponza_path();
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "Sponza not found at " << path;
    compare_scene("sponza", load_named_scene(path, scratch_dir()));
}

// Thin strands: many rays pass near edges. 640x480 so about 37k primary rays hit.
TEST(EmbreeOracle, Hairball) {
    compare_scene("hairball", load_named_scene("hairball", scratch_dir()), 640, 480);
}

TEST(EmbreeOracle, Cornell) { compare_scene("cornell", load_named_scene("cornell", scratch_dir())); }

/// The oracle is not blind: a perturbed scene (every triangle of rtsim's BVH moved) must disagree.
TEST(EmbreeOracle, DetectsWrongGeometry) {
    const Scene scene = load_named_scene("cornell", scratch_dir());
    HwBvh bvh = build_bvh(scene);
    const EmbreeScene embree(scene, EmbreeScene::Options{});
    const RaySets sets = make_ray_sets(scene, bvh, 64, 48);
    for (HwTriangle& t : bvh.triangles)
        for (float* v : {t.v0, t.v1, t.v2}) v[0] += 0.05f * (scene.bounds.hi.x - scene.bounds.lo.x);
    const Comparer cmp(bvh, embree);
    Tally primary;
    for (const Ray& r : sets.primary) cmp.closest(r, &primary);
    EXPECT_GT(primary.unexplained() + primary.t_out_of_tol, 0u);
}

}  // namespace
}  // namespace rtsim::oracle
