// check_bvh_invariants must catch corrupted trees, and sah_cost must rank a binned SAH tree
// above an object-median tree (Wald 2007's point).
#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bvh_test_scenes.h"
#include "traces/bvh/build_tree.h"
#include "traces/bvh/builder.h"
#include "traces/common/error.h"

namespace rtsim {
namespace {

/// Expects check_bvh_invariants to throw an rtsim::Error whose message contains `needle`.
void expect_caught(const HwBvh& bvh, const Scene& scene, const std::string& needle) {
    try {
        check_bvh_invariants(bvh, scene);
        ADD_FAILURE() << "corruption not caught (expected \"" << needle << "\")";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
}

/// First node with a leaf in the given slot.
uint32_t find_leaf_slot(const HwBvh& bvh, int slot) {
    for (uint32_t i = 0; i < bvh.nodes.size(); ++i) {
        uint32_t c = bvh.nodes[i].child_count[slot];
        if (c != 0 && c != kEmptyChild) return i;
    }
    return 0;
}

class Corruption : public ::testing::Test {
protected:
    Scene m_scene = test::make_scene(test::random_triangles(2000, 101));
    HwBvh m_bvh = build_bvh(m_scene);
};

TEST_F(Corruption, IntactTreePasses) { EXPECT_NO_THROW(check_bvh_invariants(m_bvh, m_scene)); }

TEST_F(Corruption, MovedTriangleVertex) {
    m_bvh.triangles[100].v1[0] += 5.0f;
    expect_caught(m_bvh, m_scene, "triangle 100");
}

TEST_F(Corruption, TrianglesSwappedAcrossLeaves) {
    std::swap(m_bvh.triangles.front(), m_bvh.triangles.back());
    expect_caught(m_bvh, m_scene, "outside the leaf box");
}

TEST_F(Corruption, ShrunkenLeafBox) {
    uint32_t node = find_leaf_slot(m_bvh, 1);
    m_bvh.nodes[node].hi(1, 2) = m_bvh.nodes[node].lo(1, 2);
    expect_caught(m_bvh, m_scene, "BVH node " + std::to_string(node) + " child 1");
}

TEST_F(Corruption, ShrunkenInteriorBox) {
    ASSERT_EQ(m_bvh.nodes[0].child_count[0], 0u);
    m_bvh.nodes[0].hi(0, 0) -= 0.1f;  // the grandchildren now stick out
    expect_caught(m_bvh, m_scene, "box outside its parent's box");
}

TEST_F(Corruption, TriangleReferencedTwice) {
    uint32_t node = find_leaf_slot(m_bvh, 0);
    m_bvh.nodes[node].child_count[0] += 1;  // overlaps the next leaf's first triangle
    m_bvh.nodes[node].hi(0, 0) = m_bvh.nodes[node].hi(0, 1) = m_bvh.nodes[node].hi(0, 2) = 2.0f;
    m_bvh.nodes[node].lo(0, 0) = m_bvh.nodes[node].lo(0, 1) = m_bvh.nodes[node].lo(0, 2) = -1.0f;
    // Widen every ancestor box too so only the double reference is wrong.
    for (HwNode& n : m_bvh.nodes)
        for (int s = 0; s < 2; ++s)
            if (n.child_count[s] == 0)
                for (int a = 0; a < 3; ++a) n.lo(s, a) = -1.0f, n.hi(s, a) = 2.0f;
    m_bvh.bounds = Aabb{Vec3(-1.0f), Vec3(2.0f)};
    expect_caught(m_bvh, m_scene, "referenced twice");
}

TEST_F(Corruption, BadChildReference) {
    m_bvh.nodes[0].child_ref[0] = uint32_t(m_bvh.nodes.size());
    expect_caught(m_bvh, m_scene, "BVH node 0 child 0: bad child reference");
}

TEST_F(Corruption, WrongPrimitiveId) {
    std::swap(m_bvh.triangles[10].prim, m_bvh.triangles[11].prim);
    expect_caught(m_bvh, m_scene, "differs from the scene's primitive");
}

TEST_F(Corruption, StrayEmptyChild) {
    uint32_t node = find_leaf_slot(m_bvh, 1);
    m_bvh.nodes[node].child_count[1] = kEmptyChild;
    expect_caught(m_bvh, m_scene, "empty child outside the root");
}

/// Object-median build (split the largest centroid axis in half by count), the baseline
/// binned SAH should beat on SAH cost.
void median_split(const std::vector<Triangle>& tris, BuildTree& tree, uint32_t node, uint32_t begin,
                  uint32_t end) {
    auto centroid = [&](uint32_t id) {
        Aabb b;
        b.grow(tris[id].v0), b.grow(tris[id].v1), b.grow(tris[id].v2);
        return b.center();
    };
    Aabb box, cbox;
    for (uint32_t i = begin; i < end; ++i) {
        const Triangle& t = tris[tree.prim_ids[i]];
        box.grow(t.v0), box.grow(t.v1), box.grow(t.v2);
        cbox.grow(centroid(tree.prim_ids[i]));
    }
    tree.nodes[node].box = box;
    if (end - begin <= 4) {
        tree.nodes[node].first = begin;
        tree.nodes[node].count = end - begin;
        return;
    }
    int axis = cbox.largest_axis();
    uint32_t mid = (begin + end) / 2;
    std::nth_element(tree.prim_ids.begin() + begin, tree.prim_ids.begin() + mid,
                     tree.prim_ids.begin() + end, [&](uint32_t a, uint32_t b) {
                         return centroid(a)[axis] < centroid(b)[axis];
                     });
    uint32_t left = uint32_t(tree.nodes.size());
    tree.nodes[node].first = left;
    tree.nodes[node].count = 0;
    tree.nodes.resize(tree.nodes.size() + 2);
    median_split(tris, tree, left, begin, mid);
    median_split(tris, tree, left + 1, mid, end);
}

TEST(BvhSah, BinnedSahBeatsMedianSplitOnClusteredScene) {
    Scene scene = test::make_scene(test::clustered_triangles(20000, 8, 37));
    BuildConfig config;
    HwBvh sah = build_bvh(scene, config);

    BuildTree median;
    median.nodes.resize(1);
    median.prim_ids.resize(scene.triangle_count());
    for (uint32_t i = 0; i < median.prim_ids.size(); ++i) median.prim_ids[i] = i;
    median_split(scene.triangles, median, 0, 0, uint32_t(median.prim_ids.size()));
    HwBvh med = flatten_bvh(median, scene, config);
    ASSERT_NO_THROW(check_bvh_invariants(med, scene));

    double sah_cost_binned = sah_cost(sah, config), sah_cost_median = sah_cost(med, config);
    EXPECT_LT(sah_cost_binned, 0.9 * sah_cost_median)
        << "binned " << sah_cost_binned << " median " << sah_cost_median;
}

}  // namespace
}  // namespace rtsim
