// validate_bvh2 (the binary BVH's load-time check, traces/accel/bvh2/bvh2.h) on images as a
// corrupt trace would carry them: each corruption is refused with a message naming the source,
// the node and child (or triangle), never traversed.
#include <string>

#include <gtest/gtest.h>

#include "tests/cpp/bvh/bvh_test_scenes.h"
#include "traces/bvh/builder.h"
#include "traces/accel/bvh2/bvh2.h"
#include "traces/common/error.h"

namespace rtsim {
namespace {

static_assert(kTraversalStackSize == 64, "validate_bvh2 assumes a 64-entry traversal stack");

HwBvh built(size_t triangles = 500) { return build_bvh(test::make_scene(test::random_triangles(triangles, 7))); }

/// The message validate_bvh2 throws for the image, or "" if it accepts it.
std::string refusal(const HwBvh& bvh) {
    try {
        validate_bvh2(bvh2_view(bvh), "corrupt.rtt");
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

/// Expects a refusal naming the file and containing every fragment.
void expect_refused(const HwBvh& bvh, const std::vector<std::string>& fragments) {
    const std::string msg = refusal(bvh);
    ASSERT_FALSE(msg.empty()) << "corrupt image accepted";
    EXPECT_EQ(msg.rfind("corrupt.rtt: ", 0), 0u) << msg;
    for (const std::string& f : fragments) EXPECT_NE(msg.find(f), std::string::npos) << "lacks '" << f << "': " << msg;
}

/// First (node, slot) that holds a leaf / an interior child.
std::pair<uint32_t, int> find_slot(const HwBvh& bvh, bool leaf) {
    for (uint32_t i = 0; i < bvh.nodes.size(); ++i)
        for (int s = 0; s < 2; ++s)
            if ((bvh.nodes[i].child_count[s] != 0) == leaf && bvh.nodes[i].child_count[s] != kEmptyChild) return {i, s};
    return {0, -1};
}

TEST(BvhImageChecks, BuiltImagesPass) {
    for (size_t n : {1, 2, 5, 500, 5000}) EXPECT_EQ(refusal(built(n)), "") << n << " triangles";
}

TEST(BvhImageChecks, EmptySections) {
    HwBvh bvh = built();
    bvh.triangles.clear();
    expect_refused(bvh, {"references triangles"});
    bvh = built();
    bvh.nodes.clear();
    expect_refused(bvh, {"no nodes but 500 triangles"});
}

TEST(BvhImageChecks, ChildIndexOutOfRange) {
    HwBvh bvh = built();
    auto [node, slot] = find_slot(bvh, false);
    bvh.nodes[node].child_ref[slot] = uint32_t(bvh.nodes.size());
    expect_refused(bvh, {"node " + std::to_string(node) + " child " + std::to_string(slot), "out of range"});
}

TEST(BvhImageChecks, SelfLoopAndCycleToRoot) {
    HwBvh bvh = built();
    auto [node, slot] = find_slot(bvh, false);
    const uint32_t child = bvh.nodes[node].child_ref[slot];
    bvh.nodes[child].child_ref[0] = child;  // the child points to itself
    bvh.nodes[child].child_count[0] = 0;
    expect_refused(bvh, {"not after its parent"});
    bvh = built();
    bvh.nodes[child].child_ref[0] = 0;  // back to the root
    bvh.nodes[child].child_count[0] = 0;
    expect_refused(bvh, {"points to node 0 (not after its parent)"});
}

TEST(BvhImageChecks, SharedSubtreeAndUnreachableNode) {
    HwBvh bvh = built();
    HwNode& root = bvh.nodes[0];
    ASSERT_EQ(root.child_count[0], 0u);
    ASSERT_EQ(root.child_count[1], 0u);
    root.child_ref[1] = root.child_ref[0];  // both children the same subtree
    expect_refused(bvh, {"two parents"});
    bvh = built();
    bvh.nodes.push_back(bvh.nodes.back());  // an extra node nobody points to
    expect_refused(bvh, {"node " + std::to_string(bvh.nodes.size() - 1), "not reachable"});
}

TEST(BvhImageChecks, LeafRangesAndCounts) {
    HwBvh bvh = built();
    auto [node, slot] = find_slot(bvh, true);
    bvh.nodes[node].child_count[slot] = 0xFFFFFF;
    expect_refused(bvh, {"leaf of 16777215 triangles"});
    bvh = built();
    bvh.nodes[node].child_ref[slot] = uint32_t(bvh.triangles.size()) - 1;
    bvh.nodes[node].child_count[slot] = 2;
    expect_refused(bvh, {"of 500"});
    bvh = built();
    bvh.nodes[node].child_ref[slot] = 0xFFFFFFFFu;  // first + count overflows 32 bits
    expect_refused(bvh, {"references triangles"});
}

TEST(BvhImageChecks, TrianglesOwnedOnceAndReachable) {
    HwBvh bvh = built();
    auto [node, slot] = find_slot(bvh, true);
    bvh.nodes[node].child_count[slot] += 1;  // overlaps the next leaf
    std::string msg = refusal(bvh);
    EXPECT_TRUE(msg.find("in two leaves") != std::string::npos ||
                msg.find("references triangles") != std::string::npos)
        << msg;
    bvh = built();
    if (bvh.nodes[node].child_count[slot] > 1) {
        bvh.nodes[node].child_count[slot] -= 1;  // its last triangle now belongs to no leaf
        expect_refused(bvh, {"in no leaf"});
    }
}

// Primitive ids are not checked for uniqueness: an SBVH image repeats a primitive in several
// leaves by design (docs/accel.md), and a repeated or large id cannot make traversal misbehave.

TEST(BvhImageChecks, EmptySlotOnlyInAOneLeafRoot) {
    HwBvh one = built(1);
    ASSERT_EQ(one.nodes[0].child_count[1], kEmptyChild);
    EXPECT_EQ(refusal(one), "");
    one.nodes[0].hi(1, 0) = 1e30f;  // the empty slot's box becomes enterable
    one.nodes[0].lo(1, 0) = -1e30f;
    expect_refused(one, {"enterable box"});
    HwBvh bvh = built();
    auto [node, slot] = find_slot(bvh, true);
    bvh.nodes[node].child_count[slot] = kEmptyChild;
    expect_refused(bvh, {"empty child slot outside the root"});
}

TEST(BvhImageChecks, NanBoxRefused) {
    HwBvh bvh = built();
    bvh.nodes[0].lo(0, 1) = std::nanf("");
    expect_refused(bvh, {"node 0 child 0", "NaN"});
}

/// A chain: node i has node i + 1 as child 0 and a one-triangle leaf as child 1; the last node
/// has two leaves. Every box is [-1, 1]^3, so a ray through it pushes one entry per level.
HwBvh chain(uint32_t depth) {
    HwBvh bvh;
    for (uint32_t i = 0; i <= depth + 1; ++i) {
        HwTriangle t{};
        t.prim = i;
        bvh.triangles.push_back(t);
    }
    for (uint32_t i = 0; i <= depth; ++i) {
        HwNode n{};
        const bool last = i == depth;
        n.child_ref[0] = last ? depth + 1 : i + 1;
        n.child_count[0] = last ? 1 : 0;
        n.child_ref[1] = i;
        n.child_count[1] = 1;
        for (int s = 0; s < 2; ++s)
            for (int a = 0; a < 3; ++a) {
                n.lo(s, a) = -1.0f;
                n.hi(s, a) = 1.0f;
            }
        bvh.nodes.push_back(n);
    }
    return bvh;
}

TEST(BvhImageChecks, DepthBoundedByTheTraversalStack) {
    const Ray ray{Vec3(0.0f, 0.0f, -5.0f), 0.0f, Vec3(0.0f, 0.0f, 1.0f), 100.0f};
    // The deepest accepted chain (interior node at depth 63) traverses without overflow...
    EXPECT_EQ(refusal(chain(kTraversalStackSize - 1)), "");
    EXPECT_NO_THROW(trace_ray(chain(kTraversalStackSize - 1), ray, TraversalMode::closest_hit));
    // ...one level deeper is refused, and would indeed overflow the stack: the bound is tight.
    expect_refused(chain(kTraversalStackSize), {"deeper than the traversal stack (64)"});
    EXPECT_THROW(trace_ray(chain(kTraversalStackSize), ray, TraversalMode::closest_hit), Error);
}

}  // namespace
}  // namespace rtsim
