// Treelet partitioning (Aila & Karras 2010): every node in exactly one treelet, budgets kept,
// deterministic, fewer treelets for bigger budgets, broken partitions caught.
#include <gtest/gtest.h>

#include <filesystem>

#include "bvh_test_scenes.h"
#include "traces/bvh/builder.h"
#include "traces/bvh/treelets.h"
#include "traces/common/error.h"
#include "traces/scene/gltf_loader.h"
#include "traces/scene/procedural.h"

using namespace rtsim;

namespace {

HwBvh random_bvh(size_t triangles, uint64_t seed) {
    return build_bvh(test::make_scene(test::random_triangles(triangles, seed)));
}

}  // namespace

TEST(Treelets, PartitionInvariantsOverBudgetsAndScenes) {
    for (size_t n : {1, 2, 7, 1000, 50000}) {
        HwBvh bvh = random_bvh(n, 11 + n);
        for (uint32_t budget : {64u, 256u, 1024u, 16384u, 1u << 20}) {
            SCOPED_TRACE(std::to_string(n) + " triangles, budget " + std::to_string(budget));
            TreeletPartition p = partition_treelets(bvh.nodes, budget);
            EXPECT_NO_THROW(check_treelet_partition(bvh.nodes, p));
            uint64_t bytes = 0, nodes = 0;
            for (const TreeletInfo& t : p.treelets) {
                EXPECT_GT(t.nodes, 0u);
                EXPECT_TRUE(t.bytes <= budget || t.nodes == 1);
                bytes += t.bytes;
                nodes += t.nodes;
            }
            EXPECT_EQ(nodes, bvh.nodes.size());  // every node exactly once
            uint64_t all = 0;
            for (const HwNode& node : bvh.nodes) all += node_footprint(node);
            EXPECT_EQ(bytes, all);
            EXPECT_EQ(p.node_treelet[0], 0u);  // the root's treelet comes first
        }
    }
}

TEST(Treelets, ProceduralScenesAndDeterminism) {
    std::string dir = (std::filesystem::temp_directory_path() / "rtsim_test_treelets").string();
    ProceduralOptions options;
    options.hairball_triangles = 30000;
    for (const std::string& name : procedural_scene_names()) {
        SCOPED_TRACE(name);
        HwBvh bvh = build_bvh(load_gltf(write_procedural_scene(name, dir, options)));
        TreeletPartition a = partition_treelets(bvh.nodes, 8192), b = partition_treelets(bvh.nodes, 8192);
        EXPECT_EQ(a.node_treelet, b.node_treelet);
        check_treelet_partition(bvh.nodes, a);
    }
}

TEST(Treelets, BiggerBudgetsMakeFewerFullerTreelets) {
    HwBvh bvh = random_bvh(100000, 5);
    size_t previous = SIZE_MAX;
    for (uint32_t kib : {4u, 16u, 64u, 256u}) {
        TreeletPartition p = partition_treelets(bvh.nodes, kib * 1024);
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
    TreeletPartition p = partition_treelets(bvh.nodes, 2048);
    ASSERT_GT(p.treelets.size(), 3u);
    TreeletPartition unassigned = p;
    unassigned.node_treelet[10] = 0xFFFFFFFFu;
    EXPECT_THROW(check_treelet_partition(bvh.nodes, unassigned), Error);
    TreeletPartition moved = p;
    moved.node_treelet[bvh.nodes.size() - 1] = (moved.node_treelet.back() + 1) % uint32_t(p.treelets.size());
    EXPECT_THROW(check_treelet_partition(bvh.nodes, moved), Error);
    TreeletPartition over = p;
    over.budget_bytes = 64;
    EXPECT_THROW(check_treelet_partition(bvh.nodes, over), Error);
    EXPECT_THROW(partition_treelets(bvh.nodes, 32), Error);
}
