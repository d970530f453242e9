// The traversal stepper: invalid rays, work counts on a hand-made BVH, tie-breaking, stack
// overflow, the alpha test, and zero differences against brute force on random scenes.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "isect_test_util.h"
#include "traces/common/error.h"
#include "traces/accel/bvh2/bvh2.h"

namespace rtsim {
namespace {

using test::kInf;
using test::make_ray;

HwTriangle make_tri(const Vec3& a, const Vec3& b, const Vec3& c, uint32_t prim, uint32_t flags = 0) {
    HwTriangle t{};
    for (int k = 0; k < 3; ++k) {
        t.v0[k] = a[k];
        t.v1[k] = b[k];
        t.v2[k] = c[k];
    }
    t.prim = prim;
    t.inst = 0;
    t.flags = flags;
    return t;
}

void set_box(HwNode& n, int slot, const Vec3& lo, const Vec3& hi, uint32_t ref, uint32_t count) {
    for (int a = 0; a < 3; ++a) {
        n.lo(slot, a) = lo[a];
        n.hi(slot, a) = hi[a];
    }
    n.child_ref[slot] = ref;
    n.child_count[slot] = count;
}

/// Root with two leaves: leaf 0 (x < 0) holds triangles 0, 1 at z = 5 and 6; leaf 1 (x > 0)
/// holds triangle 2 at z = 3, whose edge lies on x = 0.
HwBvh two_leaf_bvh() {
    HwBvh bvh;
    bvh.triangles = {make_tri(Vec3(-2, -1, 5), Vec3(0, -1, 5), Vec3(-1, 1, 5), 0),
                     make_tri(Vec3(-2, -1, 6), Vec3(0, -1, 6), Vec3(-1, 1, 6), 1),
                     make_tri(Vec3(0, -1, 3), Vec3(2, -1, 3), Vec3(0, 1, 3), 2)};
    HwNode root{};
    set_box(root, 0, Vec3(-2, -1, 5), Vec3(0, 1, 6), 0, 2);
    set_box(root, 1, Vec3(0, -1, 3), Vec3(2, 1, 3), 2, 1);
    bvh.nodes = {root};
    return bvh;
}

TEST(Traversal, InvalidRaysAreDoneAtOnceWithZeroWork) {
    const HwBvh bvh = two_leaf_bvh();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const Ray bad[] = {make_ray(Vec3(nan, 0, 0), Vec3(0, 0, 1)), make_ray(Vec3(0), Vec3(0, kInf, 1)),
                       make_ray(Vec3(0), Vec3(0.0f)), make_ray(Vec3(0), Vec3(-0.0f)),
                       make_ray(Vec3(0), Vec3(0, 0, 1), 2.0f, 1.0f), make_ray(Vec3(0), Vec3(0, 0, 1), nan),
                       make_ray(Vec3(0), Vec3(0, 0, 1), 0.0f, nan), make_ray(Vec3(0), Vec3(nan, 0, 1))};
    for (const Ray& r : bad) {
        EXPECT_FALSE(ray_is_valid(r));
        Bvh2Stepper tr(bvh2_view(bvh));
        tr.begin(r, TraversalMode::closest_hit);
        EXPECT_TRUE(tr.done());
        EXPECT_EQ(tr.plan().fetch_count, 0);
        WorkCounts w;
        const Hit h = trace_ray(bvh, r, TraversalMode::closest_hit, &w);
        EXPECT_FALSE(h.valid());
        EXPECT_EQ(w, WorkCounts{});
        EXPECT_FALSE(trace_ray_brute_force(bvh, r, TraversalMode::closest_hit).valid());
    }
}

TEST(Traversal, StepsAndWorkOnAHandMadeTree) {
    const HwBvh bvh = two_leaf_bvh();
    // Through both leaves' boxes: x = 0 lies on both boxes' shared face.
    Bvh2View view = bvh2_view(bvh);
    view.node_base = 0x1000;
    view.tri_at.base = 0x8000;
    Bvh2Stepper tr(view);
    tr.begin(make_ray(Vec3(0, 0, 0), Vec3(0, 0, 1)), TraversalMode::closest_hit);
    // The root: one 64-byte node fetch at its address, two box tests, locality key node 0.
    ASSERT_FALSE(tr.done());
    ASSERT_EQ(tr.plan().fetch_count, 1);
    EXPECT_EQ(tr.plan().fetch[0].addr, 0x1000u);
    EXPECT_EQ(tr.plan().fetch[0].bytes, 64u);
    EXPECT_EQ(tr.plan().fetch[0].kind, DataKind::node);
    ASSERT_EQ(tr.plan().op_count, 1);
    EXPECT_EQ(tr.plan().op[0].kind, OpKind::box);
    EXPECT_EQ(tr.plan().op[0].count, 2u);
    EXPECT_EQ(tr.plan().locality, 0u);
    EXPECT_EQ(tr.execute().op_count, 0);
    // Leaf 1 (entry 3) is nearer than leaf 0 (entry 5): it goes first, leaf 0 is pushed.
    ASSERT_FALSE(tr.done());
    EXPECT_EQ(tr.plan().fetch[0].addr, 0x8000u + 2 * 48);
    EXPECT_EQ(tr.plan().fetch[0].bytes, 48u);
    EXPECT_EQ(tr.plan().fetch[0].kind, DataKind::triangle);
    EXPECT_EQ(tr.plan().op[0].kind, OpKind::triangle);
    EXPECT_EQ(tr.plan().op[0].count, 1u);
    EXPECT_EQ(tr.plan().locality, kNoLocality);  // a leaf stays in its node's treelet
    EXPECT_EQ(tr.stack_size(), 1);
    tr.execute();
    // Triangle 2 hit at t = 3 (on its edge x = 0): leaf 0 (tnear 5) is skipped, no fetch.
    ASSERT_TRUE(tr.done());
    EXPECT_EQ(tr.hit().prim, 2);
    EXPECT_EQ(tr.hit().t, 3.0f);
    EXPECT_EQ(tr.work().steps, 1u);
    EXPECT_EQ(tr.work().box_tests, 2u);
    EXPECT_EQ(tr.work().tri_tests, 1u);

    // Only through leaf 0: both its triangles are tested, the nearer one wins.
    WorkCounts w;
    const Hit h = trace_ray(bvh, make_ray(Vec3(-1, 0, 0), Vec3(0, 0, 1)), TraversalMode::closest_hit, &w);
    EXPECT_EQ(h.prim, 0);
    EXPECT_EQ(h.t, 5.0f);
    EXPECT_EQ(w.steps, 1u);
    EXPECT_EQ(w.tri_tests, 2u);
    // A miss of both boxes: one node visit, no triangle test.
    EXPECT_FALSE(trace_ray(bvh, make_ray(Vec3(5, 0, 0), Vec3(0, 0, 1)), TraversalMode::closest_hit, &w).valid());
    EXPECT_EQ(w.steps, 1u);
    EXPECT_EQ(w.tri_tests, 0u);
    // tmax before leaf 0's box: leaf 0 is never entered.
    EXPECT_FALSE(trace_ray(bvh, make_ray(Vec3(-1, 0, 0), Vec3(0, 0, 1), 0.0f, 4.9f), TraversalMode::closest_hit, &w).valid());
    EXPECT_EQ(w.tri_tests, 0u);
}

TEST(Traversal, EmptySlotAndEmptyScene) {
    HwBvh bvh;
    bvh.triangles = {make_tri(Vec3(-1, -1, 2), Vec3(1, -1, 2), Vec3(0, 1, 2), 0)};
    HwNode root{};
    set_box(root, 0, Vec3(-1, -1, 2), Vec3(1, 1, 2), 0, 1);
    // An empty slot whose box would contain everything: still never entered.
    set_box(root, 1, Vec3(-100), Vec3(100), 0, kEmptyChild);
    bvh.nodes = {root};
    WorkCounts w;
    EXPECT_EQ(trace_ray(bvh, make_ray(Vec3(0), Vec3(0, 0, 1)), TraversalMode::closest_hit, &w).prim, 0);
    EXPECT_EQ(w.tri_tests, 1u);
    EXPECT_EQ(w.steps, 1u);
    EXPECT_FALSE(trace_ray(HwBvh{}, make_ray(Vec3(0), Vec3(0, 0, 1)), TraversalMode::closest_hit, &w).valid());
    EXPECT_EQ(w.steps, 0u);
}

TEST(Traversal, CoincidentTrianglesGiveTheSmallerPrim) {
    // Two identical triangles in two leaves with identical boxes, stored in both orders.
    for (int order = 0; order < 2; ++order) {
        HwBvh bvh;
        const Vec3 a(-1, -1, 2), b(1, -1, 2.5f), c(0, 1, 2.25f);
        bvh.triangles = {make_tri(a, b, c, order == 0 ? 7u : 3u), make_tri(a, b, c, order == 0 ? 3u : 7u)};
        HwNode root{};
        set_box(root, 0, Vec3(-1, -1, 2), Vec3(1, 1, 2.5f), 0, 1);
        set_box(root, 1, Vec3(-1, -1, 2), Vec3(1, 1, 2.5f), 1, 1);
        bvh.nodes = {root};
        Rng rng(order);
        for (int i = 0; i < 1000; ++i) {
            const Vec3 o = test::random_point(rng, Vec3(-0.2f, -0.2f, -1), Vec3(0.2f, 0.2f, 0));
            const Ray r = make_ray(o, Vec3(rng.next() * 0.02f, rng.next() * 0.02f, 1));
            EXPECT_EQ(trace_ray(bvh, r, TraversalMode::closest_hit).prim, 3);
        }
    }
}

TEST(Traversal, RayStartingOnASurface) {
    // Documented: tmin is excluded, so the surface the origin lies on is not hit at t = 0; the
    // ray goes on to the opposite face.
    const Scene scene = test::make_scene(test::tessellated_cube(2));
    const HwBvh bvh = test::build(scene);
    const Vec3 o(0.25f, -0.5f, 1.0f);  // on the face z = 1
    const Hit on = trace_ray(bvh, make_ray(o, Vec3(0.1f, 0.2f, -1.0f)), TraversalMode::closest_hit);
    ASSERT_TRUE(on.valid());
    EXPECT_NEAR(on.t, 2.0f, 1e-5f);
    const Hit off = trace_ray(bvh, make_ray(o, Vec3(0.1f, 0.2f, -1.0f), 1e-4f), TraversalMode::closest_hit);
    ASSERT_TRUE(off.valid());
    EXPECT_NEAR(off.t, 2.0f, 1e-5f);  // the opposite face z = -1
    EXPECT_FALSE(trace_ray(bvh, make_ray(o, Vec3(0.1f, 0.2f, 1.0f), 1e-4f), TraversalMode::closest_hit).valid());
}

TEST(Traversal, StackOverflowThrows) {
    // A chain of 70 nodes, each with a leaf and the next node, all boxes around the ray: every
    // node pushes one entry. Real BVHs (depth <= 64) never get here.
    HwBvh bvh;
    bvh.triangles = {make_tri(Vec3(50, 50, 50), Vec3(51, 50, 50), Vec3(50, 51, 50), 0)};
    for (uint32_t i = 0; i < 70; ++i) {
        HwNode n{};
        // The next node is entered first (tnear 4), the leaf (tnear 5) is pushed.
        set_box(n, 0, Vec3(-1, -1, 0), Vec3(1, 1, 1), 0, 1);
        set_box(n, 1, Vec3(-1, -1, -1), Vec3(1, 1, 1), i + 1 < 70 ? i + 1 : 0, i + 1 < 70 ? 0 : 1);
        bvh.nodes.push_back(n);
    }
    EXPECT_THROW(trace_ray(bvh, make_ray(Vec3(0, 0, -5), Vec3(0, 0, 1)), TraversalMode::closest_hit), Error);
}

TEST(Traversal, AlphaTest) {
    int accepted = 0;
    for (uint32_t prim = 0; prim < 200; ++prim)
        for (int i = 0; i < 100; ++i) {
            const float u = float(i % 10) / 10.0f, v = float(i / 10) / 10.0f;
            EXPECT_TRUE(alpha_test_accepts(prim, u, v, 255));
            EXPECT_FALSE(alpha_test_accepts(prim, u, v, 0));
            EXPECT_EQ(alpha_test_accepts(prim, u, v, 128), alpha_test_accepts(prim, u, v, 128));
            accepted += alpha_test_accepts(prim, u, v, 64);
        }
    EXPECT_NEAR(accepted / 20000.0, 64.0 / 255.0, 0.02);
    // Quantised to 1/1024: tiny differences in u, v do not change the answer.
    EXPECT_EQ(alpha_test_accepts(5, 0.50001f, 0.25f, 100), alpha_test_accepts(5, 0.50002f, 0.25f, 100));
}

TEST(Traversal, AlphaTestOfANanOrFarOutBarycentricIsDefined) {
    // A corrupt trace's triangle can give NaN or huge u, v; the decision stays deterministic.
    const float nan = std::numeric_limits<float>::quiet_NaN(), huge = 1e30f;
    EXPECT_EQ(alpha_test_accepts(3, nan, 0.5f, 100), alpha_test_accepts(3, 0.0f, 0.5f, 100));
    EXPECT_EQ(alpha_test_accepts(3, huge, -huge, 100), alpha_test_accepts(3, 4.0f, -4.0f, 100));
}

}  // namespace
}  // namespace rtsim
