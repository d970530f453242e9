// Treelet partitioning of tree structures (Aila & Karras 2010; traces/accel/locality.h) on the
// binary BVH: every node in exactly one treelet, budgets kept, deterministic, fewer treelets for
// bigger budgets, broken partitions caught.
#include <gtest/gtest.h>

#include <filesystem>

#include "bvh_test_scenes.h"
#include "traces/bvh/builder.h"
#include "traces/accel/bvh2/bvh2.h"
#include "traces/common/error.h"
#include "traces/scene/gltf_loader.h"
#include "traces/scene/procedural.h"
#include "tests/cpp/process_temp_dir.h"

using namespace rtsim;

namespace {

HwBvh random_bvh(size_t triangles, uint64_t seed) {
    return build_bvh(test::make_scene(test::random_triangles(triangles, seed)));
}

LocalityTree tree_of(const HwBvh& bvh) { return bvh2_locality_tree(bvh.nodes.data(), bvh.nodes.size()); }

LocalityPartition partition_treelets(const HwBvh& bvh, uint64_t budget) {
    return partition_tree(tree_of(bvh), budget);
}

void check_treelet_partition(const HwBvh& bvh, const LocalityPartition& p) { check_tree_partition(tree_of(bvh), p); }

}  // namespace

TEST(Treelets, PartitionInvariantsOverBudgetsAndScenes) {
    for (size_t n : {1, 2, 7, 1000, 50000}) {
        HwBvh bvh = random_bvh(n, 11 + n);
        for (uint32_t budget : {64u, 256u, 1024u, 16384u, 1u << 20}) {
            SCOPED_TRACE(std::to_string(n) + " triangles, budget " + std::to_string(budget));
            LocalityPartition p = partition_treelets(bvh, budget);
            EXPECT_NO_THROW(check_treelet_partition(bvh, p));
            uint64_t bytes = 0, nodes = 0;
            for (const TreeletInfo& t : p.treelets) {
                EXPECT_GT(t.nodes, 0u);
                EXPECT_TRUE(t.bytes <= budget || t.nodes == 1);
                bytes += t.bytes;
                nodes += t.nodes;
            }
            EXPECT_EQ(nodes, bvh.nodes.size());  // every node exactly once
            // Every node and triangle byte is in some treelet, once.
            EXPECT_EQ(bytes, bvh.nodes.size() * sizeof(HwNode) + bvh.triangles.size() * sizeof(HwTriangle));
            EXPECT_EQ(p.group_of[0], 0u);  // the root's treelet comes first
            EXPECT_EQ(p.root_group, 0u);
        }
    }
}

TEST(Treelets, ProceduralScenesAndDeterminism) {
    std::string dir = test::process_temp_dir("treelets").string();
    ProceduralOptions options;
    options.hairball_triangles = 30000;
    for (const std::string& name : procedural_scene_names()) {
        SCOPED_TRACE(name);
        HwBvh bvh = build_bvh(load_gltf(write_procedural_scene(name, dir, options)));
        LocalityPartition a = partition_treelets(bvh, 8192), b = partition_treelets(bvh, 8192);
        EXPECT_EQ(a.group_of, b.group_of);
        check_treelet_partition(bvh, a);
    }
}

TEST(Treelets, BiggerBudgetsMakeFewerFullerTreelets) {
    HwBvh bvh = random_bvh(100000, 5);
    size_t previous = SIZE_MAX;
    for (uint32_t kib : {4u, 16u, 64u, 256u}) {
        LocalityPartition p = partition_treelets(bvh, kib * 1024);
        EXPECT_LT(p.treelets.size(), previous) << kib;
        previous = p.treelets.size();
        // Packing keeps treelets reasonably full: on average at least half the budget.
        uint64_t bytes = 0;
        for (const TreeletInfo& t : p.treelets) bytes += t.bytes;
        EXPECT_GT(double(bytes) / double(p.treelets.size()), 0.5 * kib * 1024) << kib;
    }
}

TEST(Treelets, BrokenPartitionsAreCaught) {
    HwBvh bvh = random_bvh(5000, 9);
    LocalityPartition p = partition_treelets(bvh, 2048);
    ASSERT_GT(p.treelets.size(), 3u);
    LocalityPartition unassigned = p;
    unassigned.group_of[10] = 0xFFFFFFFFu;
    EXPECT_THROW(check_treelet_partition(bvh, unassigned), Error);
    LocalityPartition moved = p;
    moved.group_of[bvh.nodes.size() - 1] = (moved.group_of.back() + 1) % uint32_t(p.treelets.size());
    EXPECT_THROW(check_treelet_partition(bvh, moved), Error);
    LocalityPartition over = p;
    over.budget_bytes = 64;
    EXPECT_THROW(check_treelet_partition(bvh, over), Error);
    EXPECT_THROW(load_accel(bvh2_image(bvh, BuildConfig{}, "binned"))->partition(32), Error);
}
