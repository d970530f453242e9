// The treelet footprint table that treelet prefetching replays: lines in first-read order, each
// once per treelet, only the structure's data, the per-entry cap; and the prefetcher's streams:
// a stream entering another treelet drops only its own unsent lines, the engine sends one line
// per cycle round robin over the streams, a per-ray stream does not re-queue a recent treelet.
#include <gtest/gtest.h>

#include <vector>

#include "rtl_model/common/treelet_footprint.h"
#include "rtl_model/traversal/treelet_prefetcher.h"

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

/// Records the lines prefetched (line addresses), taking every one at once.
class LineLog : public MemIf {
public:
    Cycle access(const MemRequest& req) override {
        EXPECT_TRUE(req.prefetch);
        lines.push_back(req.addr / 64);
        return req.time;
    }
    std::vector<uint64_t> lines;
};

TreeletFootprints table_of_three() {
    TreeletFootprints t(3, 64, 0, ServedBy::l1);
    for (uint32_t treelet = 0; treelet < 3; ++treelet)
        for (uint64_t i = 0; i < 4; ++i) t.learn(treelet, (treelet * 100 + i) * 64, 64, DataKind::node);
    return t;
}

TEST(TreeletPrefetcher, StreamsTakeTurnsOneLinePerCycle) {
    TreeletFootprints t = table_of_three();
    TreeletPrefetcher p;
    p.attach(&t, 2, false);
    LineLog mem;
    p.enter(0, 0, 10);
    p.enter(1, 1, 10);
    p.drain(mem, 14);  // 4 cycles: 4 lines, alternating
    EXPECT_EQ(mem.lines, (std::vector<uint64_t>{0, 100, 1, 101}));
    p.drain(mem, 100);
    EXPECT_EQ(mem.lines.size(), 8u);
    EXPECT_EQ(p.stats_json()["sent"], 8);
}

TEST(TreeletPrefetcher, EnteringAnotherTreeletDropsOnlyThatStreamsLines) {
    TreeletFootprints t = table_of_three();
    TreeletPrefetcher p;
    p.attach(&t, 2, false);
    LineLog mem;
    p.enter(0, 0, 0);
    p.enter(1, 1, 0);
    p.drain(mem, 2);   // 0 and 100 sent
    p.enter(0, 2, 2);  // stream 0 leaves treelet 0: its 3 unsent lines are dropped
    p.drain(mem, 100);
    EXPECT_EQ(mem.lines, (std::vector<uint64_t>{0, 100, 200, 101, 201, 102, 202, 103, 203}));
    EXPECT_EQ(p.stats_json()["cancelled"], 3);
    p.enter(0, 0, 100);  // a queue's consumer picking a treelet again prefetches it again
    p.drain(mem, 200);
    EXPECT_EQ(mem.lines.size(), 13u);
}

TEST(TreeletPrefetcher, APerRayStreamQueuesNothingForARecentTreelet) {
    TreeletFootprints t = table_of_three();
    TreeletPrefetcher p;
    p.attach(&t, 1, true);
    LineLog mem;
    p.enter(0, 0, 0);
    p.drain(mem, 10);
    p.enter(0, 1, 10);  // down into a child treelet
    p.enter(0, 0, 11);  // back in the parent's: just sent, nothing queued; the child's unsent dropped
    p.drain(mem, 100);
    EXPECT_EQ(mem.lines, (std::vector<uint64_t>{0, 1, 2, 3}));
    EXPECT_EQ(p.stats_json()["entries"], 2);
    EXPECT_EQ(p.stats_json()["cancelled"], 4);
}

}  // namespace
}  // namespace rtsim
