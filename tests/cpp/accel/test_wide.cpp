// Wide and compressed BVHs (bvh4, bvh6, bvh8, cwbvh6, cwbvh8 and the octant-order variants):
// the collapse's SAH optimality, every layout's invariants, hits bit-identical to the binary BVH
// and brute force (closest and any hit) on random soups and every procedural scene, the fused
// loops equal to the steppers hit for hit and count for count, and plans that say what runs.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "accel_test_util.h"
#include "traces/accel/bvh2/bvh2.h"
#include "traces/accel/cwbvh/cwbvh.h"
#include "traces/bvh/build_tree.h"
#include "traces/bvh/builder.h"
#include "traces/isect/brute_force.h"
#include "traces/scene/gltf_loader.h"
#include "traces/scene/procedural.h"
#include "tests/cpp/process_temp_dir.h"

namespace rtsim {
namespace {

std::vector<uint32_t> sorted(std::vector<uint32_t> v) {
    std::sort(v.begin(), v.end());
    return v;
}

std::vector<uint32_t> iota(size_t n) {
    std::vector<uint32_t> v(n);
    for (size_t i = 0; i < n; ++i) v[i] = uint32_t(i);
    return v;
}

WideBuildTree collapse(const BuildTree& split, int width, Collapse method) {
    CollapseConfig c;
    c.width = width;
    c.method = method;
    return collapse_tree(split, c);
}

TEST(WideCollapse, DpIsSahOptimalAgainstGreedyAndNarrowerTrees) {
    const Scene scenes[] = {test::random_soup(3, 4000), test::make_scene(test::icosphere(4))};
    for (const Scene& scene : scenes) {
        const BuildTree split = split_large_leaves(build_binned_sah(scene.triangles, BuildConfig{}), scene.triangles, 3);
        // Width 2 greedy is the binary tree itself: every collapse of any width must cost no more.
        const double binary = wide_sah_cost(collapse(split, 2, Collapse::greedy), 1.0f, 1.0f);
        double previous = binary;
        for (int width : {2, 4, 6, 8}) {
            const WideBuildTree dp = collapse(split, width, Collapse::dp);
            const WideBuildTree greedy = collapse(split, width, Collapse::greedy);
            EXPECT_NO_THROW(check_wide_tree(dp, 3));
            EXPECT_NO_THROW(check_wide_tree(greedy, 3));
            EXPECT_EQ(sorted(dp.prims), iota(scene.triangles.size()));
            EXPECT_EQ(sorted(greedy.prims), iota(scene.triangles.size()));
            const double d = wide_sah_cost(dp, 1.0f, 1.0f), g = wide_sah_cost(greedy, 1.0f, 1.0f);
            std::printf("[ collapse ] %zu triangles, width %d: SAH binary %.2f, greedy %.2f (%zu nodes), dp %.2f "
                        "(%zu nodes)\n",
                        scene.triangles.size(), width, binary, g, greedy.nodes.size(), d, dp.nodes.size());
            EXPECT_LE(d, g * (1 + 1e-12)) << width;
            EXPECT_LE(d, previous * (1 + 1e-12)) << width;  // a narrower tree is a candidate too
            previous = d;
        }
        EXPECT_LT(previous, binary);  // 8-wide beats binary under C_t = C_i = 1
    }
}

TEST(WideCollapse, LargeLeavesAreSplitInsideTheirBoxes) {
    const Scene scene = test::random_soup(8, 3000);
    BuildConfig config;
    config.max_leaf_size = 16;
    config.traversal_cost = 4.0f;  // makes big leaves worth it for the SAH
    const BuildTree tree = build_binned_sah(scene.triangles, config);
    uint32_t biggest = 0;
    for (const BuildNode& n : tree.nodes) biggest = std::max(biggest, n.count);
    ASSERT_GT(biggest, 3u);
    const BuildTree split = split_large_leaves(tree, scene.triangles, 3);
    EXPECT_EQ(sorted(split.prim_ids), iota(scene.triangles.size()));
    for (const BuildNode& n : split.nodes) {
        if (!n.is_leaf()) {
            EXPECT_TRUE(n.box.contains(split.nodes[n.first].box) && n.box.contains(split.nodes[n.first + 1].box));
            continue;
        }
        EXPECT_LE(n.count, 3u);
        for (uint32_t k = n.first; k < n.first + n.count; ++k) {
            const Triangle& t = scene.triangles[split.prim_ids[k]];
            Aabb b;
            b.grow(t.v0), b.grow(t.v1), b.grow(t.v2);
            EXPECT_TRUE(n.box.contains(b));
        }
    }
}

/// Every slot's decoded box contains the bounds of every triangle beneath it; returns the
/// number of leaves. Nodes come after their parents, so one reverse pass computes the bounds.
template <class Codec>
uint64_t check_boxes_contain_triangles(const Accel& accel) {
    const Region& nodes = accel.image().region("nodes");
    const HwTriangle* tris = test::triangles_of(accel).records<HwTriangle>();
    std::vector<Aabb> under(nodes.count);
    uint64_t leaves = 0;
    for (uint64_t i = nodes.count; i-- > 0;) {
        DecodedNode d;
        Codec::decode(nodes.records<typename Codec::Node>()[i], d);
        for (uint32_t m = d.valid; m; m &= m - 1) {
            const int s = __builtin_ctz(m);
            Aabb exact;
            if (d.count[s] == 0) {
                exact = under[d.ref[s]];
            } else {
                ++leaves;
                for (uint32_t k = d.ref[s]; k < d.ref[s] + d.count[s]; ++k)
                    for (const float* v : {tris[k].v0, tris[k].v1, tris[k].v2}) exact.grow(Vec3(v[0], v[1], v[2]));
            }
            const Aabb slot{Vec3(d.lo[0][s], d.lo[1][s], d.lo[2][s]), Vec3(d.hi[0][s], d.hi[1][s], d.hi[2][s])};
            EXPECT_TRUE(slot.contains(exact)) << accel.kind() << " node " << i << " slot " << s;
            under[i].grow(exact);
        }
    }
    return leaves;
}

uint64_t check_layout(const Accel& accel) {
    const std::string& k = accel.kind();
    if (k == "bvh4") return check_boxes_contain_triangles<Fp32Codec<4>>(accel);
    if (k == "bvh6") return check_boxes_contain_triangles<Fp32Codec<6>>(accel);
    if (k == "bvh8" || k == "bvh8_octant") return check_boxes_contain_triangles<Fp32Codec<8>>(accel);
    if (k == "cwbvh6") return check_boxes_contain_triangles<Cw6Codec>(accel);
    return check_boxes_contain_triangles<Cw8Codec>(accel);
}

TEST(WideImage, LayoutInvariantsOfEveryKind) {
    const Scene scene = test::random_soup(11, 3000);
    const std::map<std::string, uint32_t> node_bytes = {{"bvh4", 128},  {"bvh6", 192},   {"bvh8", 256},
                                                        {"cwbvh6", 64}, {"cwbvh8", 80},  {"bvh8_octant", 256},
                                                        {"cwbvh8_octant", 80}};
    for (const std::string& kind : test::wide_kinds()) {
        const auto accel = test::build_kind(scene, kind);
        const AccelImage& image = accel->image();
        const Region& nodes = image.region("nodes");
        EXPECT_EQ(nodes.record_bytes, node_bytes.at(kind)) << kind;
        EXPECT_EQ(image.stats["nodes"].get<uint64_t>(), nodes.count) << kind;
        EXPECT_EQ(image.stats["leaves"].get<uint64_t>(), check_layout(*accel)) << kind;
        // Every scene triangle exactly once (the binned builder duplicates none).
        std::vector<uint32_t> prims;
        const Region& tris = test::triangles_of(*accel);
        for (uint64_t i = 0; i < tris.count; ++i) prims.push_back(tris.records<HwTriangle>()[i].prim);
        EXPECT_EQ(sorted(prims), iota(scene.triangles.size())) << kind;
        EXPECT_LE(image.stats["max_leaf_size"].get<uint32_t>(), 3u);
        const int width = image.stats["width"].get<int>();
        EXPECT_GE(accel->max_stack_entries(), uint32_t(width - 1)) << kind;
        EXPECT_LE(accel->max_stack_entries(), uint32_t(width - 1) * (image.stats["max_depth"].get<uint32_t>())) << kind;
        EXPECT_LT(image.stats["sah_cost"].get<double>(), 1e9);
    }
}

/// Traces `rays` random rays through `accel` with its fused loops (best and SSE2) and its stepper
/// (hits, work and plans checked) and against the binary BVH. Returns the closest hits.
int compare_with_bvh2(const Accel& accel, const Accel& bvh2, const Aabb& bounds, uint64_t seed, int rays) {
    Rng rng(seed);
    const Region& tris = test::triangles_of(accel);
    const uint32_t node_bytes = accel.image().region("nodes").record_bytes;
    std::unique_ptr<Stepper> stepper = accel.make_stepper();
    int hits = 0;
    for (int i = 0; i < rays; ++i) {
        const Ray r = test::random_ray(rng, bounds, tris.records<HwTriangle>(), tris.count);
        for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
            WorkCounts fused_work, ref_work;
            const Hit fused = accel.trace(r, mode, &fused_work);
            const Hit ref = bvh2.trace(r, mode, &ref_work);
            // Drive the stepper by hand: the plans must say what the step then counts.
            stepper->begin(r, mode);
            uint32_t node_plans = 0, boxes = 0;
            while (!stepper->done()) {
                const StepPlan& p = stepper->plan();
                if (p.op[0].kind == OpKind::box) {
                    ++node_plans;
                    boxes += p.op[0].count;
                    EXPECT_EQ(p.fetch[0].bytes, node_bytes);
                }
                stepper->execute();
                EXPECT_LE(uint32_t(stepper->stack_size()), accel.max_stack_entries());
            }
            EXPECT_EQ(stepper->work().steps, node_plans);
            EXPECT_EQ(stepper->work().box_tests, boxes);
            EXPECT_TRUE(test::same_hit(fused, stepper->hit())) << accel.kind() << " ray " << i;
            bool ran = false;
            WorkCounts sse_work;
            const Hit sse = test::trace_sse2(accel, r, mode, &sse_work, &ran);
            if (ran) {
                EXPECT_TRUE(test::same_hit(sse, stepper->hit()) && sse_work == stepper->work()) << accel.kind() << " SSE2";
            }
            EXPECT_TRUE(fused_work == stepper->work()) << accel.kind() << " ray " << i << " steps " << fused_work.steps
                                                       << " vs " << stepper->work().steps;
            if (mode == TraversalMode::closest_hit) {
                EXPECT_TRUE(test::same_hit(fused, ref)) << accel.kind() << " ray " << i << ": prim " << fused.prim
                                                        << " t " << fused.t << ", bvh2 " << ref.prim << " t " << ref.t;
                hits += fused.valid();
            } else {
                EXPECT_EQ(fused.valid(), ref.valid()) << accel.kind() << " any-hit ray " << i;
            }
            if (::testing::Test::HasFailure()) return hits;
        }
    }
    return hits;
}

TEST(WideTrace, RandomSoupsEqualBvh2AndStepper) {
    std::printf("[ fused ] 8-wide node test: %s\n", wide_simd_has_avx() ? "AVX (and SSE2 checked too)" : "SSE2");
    for (uint64_t seed = 1; seed <= 4; ++seed) {
        const Scene scene = test::random_soup(seed, 200 + int(seed) * 700);
        const auto bvh2 = test::build_kind(scene, "bvh2", uint32_t(seed));
        for (const std::string& kind : test::wide_kinds()) {
            const auto accel = test::build_kind(scene, kind, uint32_t(seed));
            const int hits = compare_with_bvh2(*accel, *bvh2, scene.bounds, seed * 31, 4000);
            EXPECT_GT(hits, 400) << kind;
        }
    }
}

TEST(WideTrace, BruteForceAgrees) {
    const Scene scene = test::random_soup(21, 1500);
    Rng rng(5);
    for (const std::string& kind : test::wide_kinds()) {
        const auto accel = test::build_kind(scene, kind);
        const Region& tris = test::triangles_of(*accel);
        int diffs = 0;
        for (int i = 0; i < 3000; ++i) {
            const Ray r = test::random_ray(rng, scene.bounds, tris.records<HwTriangle>(), tris.count);
            const Hit a = accel->trace(r, TraversalMode::closest_hit);
            const Hit b = trace_ray_brute_force(tris.records<HwTriangle>(), tris.count, r, TraversalMode::closest_hit);
            diffs += !test::same_hit(a, b);
            diffs += accel->trace(r, TraversalMode::any_hit).valid() !=
                     trace_ray_brute_force(tris.records<HwTriangle>(), tris.count, r, TraversalMode::any_hit).valid();
        }
        EXPECT_EQ(diffs, 0) << kind;
    }
}

TEST(WideTrace, ProceduralScenesEqualBvh2) {
    const std::string dir = test::process_temp_dir("wide").string();
    ProceduralOptions options;
    options.hairball_triangles = 20000;
    for (const std::string& name : procedural_scene_names()) {
        const Scene scene = load_gltf(write_procedural_scene(name, dir, options));
        const auto bvh2 = test::build_kind(scene, "bvh2");
        for (const std::string& kind : test::wide_kinds()) {
            const auto accel = test::build_kind(scene, kind);
            const int hits = compare_with_bvh2(*accel, *bvh2, scene.bounds, 4242, 2500);
            EXPECT_GT(hits, 250) << name << " " << kind;
        }
    }
}

TEST(WideTrace, SingleTriangleScene) {
    const Scene one = test::make_scene({Vec3(-1, -1, 0), Vec3(1, -1, 0), Vec3(0, 1, 0)});
    const auto bvh2 = test::build_kind(one, "bvh2");
    for (const std::string& kind : test::wide_kinds()) {
        const auto accel = test::build_kind(one, kind);
        EXPECT_EQ(accel->image().region("nodes").count, 1u) << kind;
        EXPECT_GT(compare_with_bvh2(*accel, *bvh2, Aabb{Vec3(-2), Vec3(2)}, 9, 2000), 100) << kind;
    }
}

}  // namespace
}  // namespace rtsim
