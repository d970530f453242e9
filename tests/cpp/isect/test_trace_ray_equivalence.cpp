// trace_ray (the fused loop) against trace_ray_stepper (the Traversal stepper the model drives):
// bit-identical hits and identical work counts on every ray, closest and any hit, on random
// soups and on the procedural scenes read back through the glTF loader.
#include <cstdio>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "isect_test_util.h"
#include "traces/accel/bvh2/bvh2.h"
#include "traces/scene/gltf_loader.h"
#include "traces/scene/procedural.h"
#include "tests/cpp/process_temp_dir.h"

namespace rtsim {
namespace {


Ray random_ray(Rng& rng, const HwBvh& bvh, const Aabb& bounds) {
    return test::random_ray(rng, bounds, bvh.triangles.data(), bvh.triangles.size());
}

::testing::AssertionResult same(const Hit& a, const WorkCounts& wa, const Hit& b,
                                const WorkCounts& wb) {
    if (a.prim != b.prim || a.inst != b.inst || test::float_bits(a.t) != test::float_bits(b.t) ||
        test::float_bits(a.u) != test::float_bits(b.u) ||
        test::float_bits(a.v) != test::float_bits(b.v))
        return ::testing::AssertionFailure() << "hit: fused prim " << a.prim << " t " << a.t
                                             << ", stepper prim " << b.prim << " t " << b.t;
    if (wa != wb)
        return ::testing::AssertionFailure()
               << "work: fused steps " << wa.steps << " tris " << wa.tri_tests << " anyhit "
               << wa.anyhit_calls << ", stepper steps " << wb.steps << " tris " << wb.tri_tests
               << " anyhit " << wb.anyhit_calls;
    return ::testing::AssertionSuccess();
}

/// Traces `rays` random rays both ways in both modes; returns the number of closest hits.
int compare_all(const HwBvh& bvh, const Aabb& bounds, uint64_t seed, int rays) {
    Rng rng(seed);
    int hits = 0;
    for (int i = 0; i < rays; ++i) {
        const Ray r = random_ray(rng, bvh, bounds);
        for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
            WorkCounts wa, wb;
            const Hit a = trace_ray(bvh, r, mode, &wa);
            const Hit b = trace_ray_stepper(bvh, r, mode, &wb);
            EXPECT_TRUE(same(a, wa, b, wb)) << "ray " << i << " mode " << int(mode);
            if (::testing::Test::HasFailure()) return hits;
            hits += mode == TraversalMode::closest_hit && a.valid();
        }
    }
    return hits;
}

TEST(TraceRayEquivalence, RandomSoups) {
    const uint32_t leaf_sizes[] = {1, 2, 4, 8};
    for (uint64_t seed = 1; seed <= 8; ++seed) {
        const Scene scene = test::random_soup(seed, 50 + int(seed) * 300);
        const HwBvh bvh = test::build(scene, leaf_sizes[seed % 4]);
        const int hits = compare_all(bvh, scene.bounds, seed * 977, 20000);
        EXPECT_GT(hits, 1000) << "seed " << seed;  // the rays must exercise hits, not only misses
        std::printf("[ fused=step ] soup seed %llu: %zu triangles, 20000 rays, %d closest hits\n",
                    (unsigned long long)seed, scene.triangles.size(), hits);
    }
}

TEST(TraceRayEquivalence, SingleLeafAndEmptyScenes) {
    // One triangle: the root's child 1 is an empty slot.
    const Scene one = test::make_scene({Vec3(-1, -1, 0), Vec3(1, -1, 0), Vec3(0, 1, 0)});
    const HwBvh bvh = test::build(one);
    ASSERT_EQ(bvh.nodes[0].child_count[1], kEmptyChild);
    EXPECT_GT(compare_all(bvh, Aabb{Vec3(-2), Vec3(2)}, 5, 5000), 100);
    const HwBvh empty;
    compare_all(empty, Aabb{Vec3(-1), Vec3(1)}, 6, 100);
}

TEST(TraceRayEquivalence, ProceduralScenes) {
    const std::string dir = rtsim::test::process_temp_dir("trace_ray_equivalence").string();
    ProceduralOptions options;
    options.hairball_triangles = 20000;
    for (const std::string& name : procedural_scene_names()) {
        const Scene scene = load_gltf(write_procedural_scene(name, dir, options));
        const HwBvh bvh = build_bvh(scene, BuildConfig{});
        const int hits = compare_all(bvh, scene.bounds, 4242, 20000);
        EXPECT_GT(hits, 1000) << name;
        std::printf("[ fused=step ] %s: %zu triangles, 20000 rays, %d closest hits\n", name.c_str(),
                    scene.triangles.size(), hits);
    }
}

}  // namespace
}  // namespace rtsim
