// The treelet footprint table that treelet prefetching replays: lines in first-read order, each
// once per treelet, only the structure's data, the per-entry cap.
#include <gtest/gtest.h>

#include <vector>

#include "rtl_model/common/treelet_footprint.h"

namespace rtsim {
namespace {

std::vector<uint64_t> lines_of(const TreeletFootprints& t, uint32_t treelet) {
    std::vector<uint64_t> out;
    t.for_each_prefetch(treelet, [&](const FootprintLine& l) { out.push_back(l.line); });
    return out;
}

TEST(TreeletFootprints, LearnsLinesOnceInFirstReadOrder) {
    TreeletFootprints t(3, 64, 0, ServedBy::l1);
    t.learn(1, 640, 32, DataKind::node);        // line 10
    t.learn(1, 120, 16, DataKind::triangle);    // spans lines 1 and 2
    t.learn(1, 650, 8, DataKind::node);         // line 10 again: known
    t.learn(2, 640, 32, DataKind::node);        // another treelet keeps its own list
    EXPECT_EQ(lines_of(t, 1), (std::vector<uint64_t>{10, 1, 2}));
    EXPECT_EQ(lines_of(t, 2), (std::vector<uint64_t>{10}));
    EXPECT_TRUE(lines_of(t, 0).empty());
    EXPECT_EQ(t.lines_learnt(), 4u);
    EXPECT_EQ(t.treelets_learnt(), 2u);
}

TEST(TreeletFootprints, CapsLinesPerEntryRootFirst) {
    TreeletFootprints t(1, 64, 2, ServedBy::l2);
    for (uint64_t line : {7, 3, 9}) t.learn(0, line * 64, 64, DataKind::node);
    EXPECT_EQ(lines_of(t, 0), (std::vector<uint64_t>{7, 3}));
    EXPECT_EQ(t.into(), ServedBy::l2);
}

TEST(TreeletFootprints, LearnsOnlyTheStructuresData) {
    EXPECT_TRUE(TreeletFootprints::learns(DataKind::node));
    EXPECT_TRUE(TreeletFootprints::learns(DataKind::triangle));
    EXPECT_TRUE(TreeletFootprints::learns(DataKind::prim_ref));
    EXPECT_FALSE(TreeletFootprints::learns(DataKind::ray));
    EXPECT_FALSE(TreeletFootprints::learns(DataKind::stack));
    EXPECT_FALSE(TreeletFootprints::learns(DataKind::ray_buffer));
}

}  // namespace
}  // namespace rtsim
