// The verdict's pieces that need no simulation: which knob relaxes which resource, and how a
// read's wait is split in the cycle accounting. (Whole runs: tests/python/test_why_slow.py.)
#include <gtest/gtest.h>

#include "rtl_model/traversal/cycle_accounting.h"
#include "sim/report/verdict.h"

namespace rtsim {
namespace {

TEST(Verdict, EachResourceHasItsKnobDoubled) {
    SimConfig c;
    struct Case {
        const char* resource;
        const char* key;
        uint64_t from, to;
    };
    c.l1.mshrs = 8;
    c.l2.mshrs = 32;
    const Case cases[] = {{"l1_mshrs", "l1.mshrs", 8, 16},      {"l2_mshrs", "l2.mshrs", 32, 64},
                          {"dram", "dram.channels", 2, 4},      {"l2_banks", "l2.banks", 8, 16},
                          {"latency", "traversal.ray_contexts", 16, 32},
                          {"scheduler", "traversal.units", 8, 16}, {"box", "box.width", 2, 4},
                          {"stack", "traversal.stack_entries", 8, 16}};
    for (const Case& k : cases) {
        const Relaxation r = relaxation_for(k.resource, c);
        EXPECT_EQ(r.key, k.key) << k.resource;
        EXPECT_EQ(r.from.get<uint64_t>(), k.from) << k.resource;
        EXPECT_EQ(r.to.get<uint64_t>(), k.to) << k.resource;
    }
    // A shared pool grows; a pipeline issuing every other cycle issues every cycle.
    c.triangle.sharing = Sharing::shared;
    EXPECT_EQ(relaxation_for("triangle", c).key, "triangle.shared_count");
    c.box.initiation_interval = 4;
    EXPECT_EQ(relaxation_for("box", c).key, "box.initiation_interval");
    EXPECT_EQ(relaxation_for("box", c).to.get<uint64_t>(), 2u);
    c.traversal.issue_cycles = 2;
    EXPECT_EQ(relaxation_for("scheduler", c).key, "traversal.issue_cycles");
    // At its range's end, or for the workload itself, there is no knob.
    c.l2.mshrs = 1024;
    EXPECT_TRUE(relaxation_for("l2_mshrs", c).key.empty());
    EXPECT_TRUE(relaxation_for("workload", c).key.empty());
}

TEST(CycleAccounting, AReadsWaitIsSplitMshrsFirstThenItsLevel) {
    CycleAccount a;
    AccessInfo info;
    info.level = ServedBy::dram;
    info.mshr_wait[0] = 30;
    info.mshr_wait[1] = 50;
    account_memory(a, 100, 400, info);
    EXPECT_EQ(a[CycleUse::l1_mshr_full], 30u);
    EXPECT_EQ(a[CycleUse::l2_mshr_full], 50u);
    EXPECT_EQ(a[CycleUse::dram], 220u);
    EXPECT_EQ(a.total(), 300u);
    // Waits reported beyond the read's own time never make the parts exceed it.
    CycleAccount b;
    info.mshr_wait[0] = 1000;
    account_memory(b, 0, 10, info);
    EXPECT_EQ(b.total(), 10u);
    EXPECT_EQ(b[CycleUse::l1_mshr_full], 10u);
    EXPECT_EQ(cycle_use_name(pipe_use(OpKind::box)), "pipe_box");
    EXPECT_EQ(cycle_use_name(CycleUse::l2_mshr_full), "l2_mshr_full");
}

}  // namespace
}  // namespace rtsim
