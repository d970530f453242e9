// The verdict's pieces that need no simulation: which knob relaxes which resource, and how a
// read's wait is split in the cycle accounting. (Whole runs: tests/python/test_why_slow.py.)
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>

#include "rtl_model/traversal/cycle_accounting.h"
#include "sim/report/verdict.h"

namespace rtsim {
namespace {

TEST(Verdict, EachResourceHasItsKnobDoubled) {
    SimConfig c;
    c.traversal.ray_contexts = 16;  // as the run's resolution step derives it (the verdict sees resolved configs)
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

TEST(Verdict, EveryKnobIsACandidate) {
    SimConfig c;
    c.traversal.ray_contexts = 16;  // resolved
    std::set<std::string> keys;
    for (const Knob& k : every_knob(c, {OpKind::box, OpKind::triangle})) keys.insert(k.relax.key);
    for (const char* key : {"traversal.units", "traversal.ray_contexts", "box.width", "triangle.width", "l1.size_kib",
                            "l2.size_kib", "l1.banks", "l2.banks", "l1.mshrs", "l2.mshrs", "dram.channels",
                            "traversal.stack_entries"})
        EXPECT_TRUE(keys.count(key)) << key;
    EXPECT_FALSE(keys.count("treelets.admit_outstanding"));  // treelets off: no ray buffer to relax
    c.treelets.enabled = true;
    std::map<std::string, bool> estimable;
    for (const Knob& k : every_knob(c, {OpKind::box})) estimable[k.relax.key] = k.estimable;
    ASSERT_TRUE(estimable.count("treelets.admit_outstanding"));
    EXPECT_FALSE(estimable["treelets.admit_outstanding"]);  // measured, never estimated
    EXPECT_TRUE(estimable.count("treelets.buffer_kib") && estimable.count("treelets.policy"));
}

/// A machine bound by DRAM channels and L2 MSHRs at once: doubling either alone buys nothing,
/// both together twice the speed. The weighing must report the pair as a co-limit.
TEST(Verdict, CoLimitsAreFoundWithTheirJointFigure) {
    SimConfig c;
    c.dram.channels = 2;
    c.l2.mshrs = 32;
    auto cycles = [](const SimConfig& x) {
        return std::max({400.0 / x.dram.channels, 6400.0 / x.l2.mshrs, 60.0 * 8 / x.traversal.units});
    };
    WeighInputs in{c, nlohmann::json::array(), cycles, cycles(c), "", {}};
    const nlohmann::json w = weigh_knobs(in);
    ASSERT_FALSE(w["co_limits"].empty()) << w.dump(1);
    const nlohmann::json& co = w["co_limits"][0];
    const std::set<std::string> keys = {co["keys"][0].get<std::string>(), co["keys"][1].get<std::string>()};
    EXPECT_EQ(keys, std::set<std::string>({"dram.channels", "l2.mshrs"}));
    EXPECT_NEAR(co["joint"].get<double>(), 2.0, 1e-9);
    EXPECT_NEAR(co["alone"][0].get<double>(), 1.0, 1e-9);
    EXPECT_EQ(w["top"].size(), 3u);
    // Not covered (treelets): nothing estimated, no co-limits, the knobs ranked by evidence.
    in.not_covered = "treelets";
    in.evidence = {{"l2_mshrs", 0.5}};
    const nlohmann::json u = weigh_knobs(in);
    EXPECT_TRUE(u["co_limits"].empty());
    EXPECT_EQ(u["top"][0]["key"], "l2.mshrs");
    EXPECT_TRUE(u["top"][0]["speedup"].is_null());
    EXPECT_EQ(u["top"][0]["why_not"], "treelets");
}

/// Gain per added area: knobs the area model prices (SRAM, pipelines) get one; MSHRs do not.
TEST(Verdict, KnobsArePricedByTheAreaModel) {
    SimConfig c;
    auto cycles = [](const SimConfig& x) { return 1000.0 * 32 / x.l2.size_kib / 128 + 1000.0 * 16 / x.l2.mshrs / 16; };
    const nlohmann::json w = weigh_knobs({c, nlohmann::json::array(), cycles, cycles(c), "", {}});
    for (const nlohmann::json& k : w["knobs"]) {
        if (k["key"] == "l2.size_kib") {
            EXPECT_GT(k["added_mm2"].get<double>(), 0.0);
            EXPECT_TRUE(k["gain_per_mm2"].is_number());
        }
        if (k["key"] == "l2.mshrs") EXPECT_TRUE(k["gain_per_mm2"].is_null());
    }
    ASSERT_FALSE(w["top_per_mm2"].empty());
    EXPECT_EQ(w["top_per_mm2"][0]["key"], "l2.size_kib");
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
