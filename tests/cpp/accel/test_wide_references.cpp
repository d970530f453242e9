// The wide and compressed BVHs from binary trees other than the binned builder's: trees whose
// leaves reference duplicated primitives (as a spatial-split builder makes), leaves larger than
// a wide leaf holds, and a lopsided tree. Hits equal brute force; every reference is stored.
#include <gtest/gtest.h>

#include <functional>

#include "accel_test_util.h"
#include "traces/accel/cwbvh/cwbvh.h"
#include "traces/isect/brute_force.h"

namespace rtsim {
namespace {

Aabb bounds_of(const Scene& scene, const std::vector<uint32_t>& refs, size_t begin, size_t end) {
    Aabb b;
    for (size_t i = begin; i < end; ++i) {
        const Triangle& t = scene.triangles[refs[i]];
        b.grow(t.v0), b.grow(t.v1), b.grow(t.v2);
    }
    return b;
}

/// A binary tree over `refs` (primitive ids, duplicates allowed): object-median splits down to
/// leaves of at most `leaf` references, or, when `lopsided`, one reference peeled off per level.
BuildTree tree_over(const Scene& scene, std::vector<uint32_t> refs, uint32_t leaf, bool lopsided) {
    BuildTree t;
    t.prim_ids = std::move(refs);
    t.nodes.push_back(BuildNode{});
    std::function<void(uint32_t, size_t, size_t)> build = [&](uint32_t n, size_t begin, size_t end) {
        t.nodes[n].box = bounds_of(scene, t.prim_ids, begin, end);
        if (end - begin <= leaf) {
            t.nodes[n].first = uint32_t(begin), t.nodes[n].count = uint32_t(end - begin);
            return;
        }
        const int axis = t.nodes[n].box.largest_axis();
        auto centre = [&](uint32_t p) { return scene.triangles[p].v0[axis] + scene.triangles[p].v1[axis]; };
        std::sort(t.prim_ids.begin() + begin, t.prim_ids.begin() + end,
                  [&](uint32_t a, uint32_t b) { return centre(a) < centre(b) || (centre(a) == centre(b) && a < b); });
        const size_t mid = lopsided ? begin + 1 : (begin + end) / 2;
        const uint32_t first = uint32_t(t.nodes.size());
        t.nodes.resize(t.nodes.size() + 2);
        t.nodes[n].first = first, t.nodes[n].count = 0;
        build(first, begin, mid);
        build(first + 1, mid, end);
    };
    build(0, 0, t.prim_ids.size());
    return t;
}

std::unique_ptr<Accel> load(const Scene& scene, const BuildTree& tree, const std::string& kind) {
    const int width = kind.back() - '0';
    const WideBuildTree wide = make_wide_tree(tree, scene, width, BuildConfig{}, ChildOrder::distance);
    if (kind.rfind("cwbvh", 0) == 0) return load_cwbvh(cwbvh_image(wide, scene, kind, ChildOrder::distance), width, kind);
    return load_wide_fp32(wide_image(wide, scene, kind, ChildOrder::distance), width, kind);
}

void expect_brute_force_hits(const Accel& accel, const Scene& scene, uint64_t seed) {
    const Region& tris = test::triangles_of(accel);
    Rng rng(seed);
    int hits = 0;
    for (int i = 0; i < 1200; ++i) {
        const Ray r = test::random_ray(rng, scene.bounds, tris.records<HwTriangle>(), tris.count);
        for (TraversalMode mode : {TraversalMode::closest_hit, TraversalMode::any_hit}) {
            WorkCounts fused_work, step_work;
            const Hit h = accel.trace(r, mode, &fused_work);
            std::unique_ptr<Stepper> s = accel.make_stepper();
            EXPECT_TRUE(test::same_hit(h, trace_with_stepper(*s, r, mode, &step_work)) && fused_work == step_work);
            const Hit b = trace_ray_brute_force(tris.records<HwTriangle>(), tris.count, r, mode);
            if (mode == TraversalMode::closest_hit) {
                ASSERT_TRUE(test::same_hit(h, b)) << accel.kind() << " ray " << i;
                hits += h.valid();
            } else {
                ASSERT_EQ(h.valid(), b.valid()) << accel.kind() << " any-hit ray " << i;
            }
        }
    }
    EXPECT_GT(hits, 120) << accel.kind();
}

TEST(WideReferences, DuplicatedReferencesBigLeavesAndLopsidedTrees) {
    const Scene scene = test::random_soup(13, 1500);
    Rng rng(99);
    std::vector<uint32_t> refs;
    for (uint32_t p = 0; p < scene.triangles.size(); ++p) {
        refs.push_back(p);
        if (rng.next() < 0.3f) refs.push_back(p);  // a second reference, elsewhere in the tree
    }
    const std::vector<BuildTree> trees = {tree_over(scene, refs, 2, false), tree_over(scene, refs, 9, false),
                                          tree_over(scene, std::vector<uint32_t>(refs.begin(), refs.begin() + 60), 1, true)};
    for (const BuildTree& tree : trees)
        for (const std::string kind : {"bvh4", "bvh6", "bvh8", "cwbvh6", "cwbvh8"}) {
            const auto accel = load(scene, tree, kind);
            EXPECT_EQ(test::triangles_of(*accel).count, tree.prim_ids.size()) << kind;  // every reference kept
            expect_brute_force_hits(*accel, scene, 5);
        }
}

}  // namespace
}  // namespace rtsim
