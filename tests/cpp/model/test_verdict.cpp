// The verdict's pieces that need no simulation: which knob relaxes which resource, and how a
// read's wait is split in the cycle accounting. (Whole runs: tests/python/test_why_slow.py.)
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>

#include "rtl_model/traversal/cycle_accounting.h"
#include "sim/report/resources.h"
#include "sim/report/technique_cost.h"
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

TEST(Verdict, StructuralAlternativesAreMeasuredAndPriced) {
    SimConfig c;
    c.traversal.ray_contexts = 16;
    StructureTraits st;
    st.kind = "bvh2";
    st.trace = "t/trace.rtt";
    std::map<std::string, Knob> by_key;
    for (const Knob& k : structural_knobs(c, st)) by_key[k.relax.key + "=" + k.relax.to.dump()] = k;
    for (const char* key : {"accel=\"bvh8\"", "accel=\"cwbvh8\"", "compressed_leaves=true", "treelets.enabled=true",
                            "traversal.model=\"simt\"", "dispatch.sort=\"morton\"", "treelets.prefetch=true"})
        EXPECT_TRUE(by_key.count(key)) << key;
    const Knob& cw = by_key.at("accel=\"cwbvh8\"");
    EXPECT_TRUE(cw.structural && cw.trace && !cw.estimable);
    EXPECT_NE(measure_command(cw, st).find("--accel cwbvh8"), std::string::npos);
    EXPECT_NE(measure_command(by_key.at("treelets.enabled=true"), st).find("--set treelets.enabled=true"),
              std::string::npos);
    // Compressed nodes have no further compressed step; two levels offer no structure.
    st.kind = "cwbvh8";
    for (const Knob& k : structural_knobs(c, st)) EXPECT_NE(k.relax.key, "accel");
    // Priced: compressed leaves add their decoders, every alternative is never estimated.
    st.kind = "bvh2";
    const nlohmann::json w = weigh_knobs({c, nlohmann::json::array(), {}, 0, "", {}, {}, st});
    bool leaves = false;
    for (const nlohmann::json& k : w["structural"]) {
        EXPECT_TRUE(k["speedup"].is_null());
        if (k["key"] == "compressed_leaves") leaves = k["added_mm2"].get<double>() > 0;
    }
    EXPECT_TRUE(leaves);
}

TEST(Verdict, ANearTieGoesToTheKnobThatRemovesTraffic) {
    SimConfig c;
    c.traversal.ray_contexts = 16;
    // More channels estimated 2 points ahead of twice the L2, which alone removes DRAM traffic.
    auto cycles = [](const SimConfig& x) {
        return 1000.0 / (x.dram.channels == 4 ? 1.16 : 1.0) / (x.l2.size_kib == 2048 ? 1.14 : 1.0);
    };
    auto bytes = [](const SimConfig& x) { return x.l2.size_kib == 2048 ? 850.0 : 1000.0; };
    WeighInputs in{c, nlohmann::json::array(), cycles, cycles(c), "", {}};
    in.dram_bytes = bytes;
    const nlohmann::json w = weigh_knobs(in);
    EXPECT_EQ(w["knobs"][0]["key"], "l2.size_kib");
    EXPECT_TRUE(w["knobs"][0].contains("tie_break"));
    EXPECT_NEAR(w["knobs"][0]["dram_saved_fraction"].get<double>(), 0.15, 1e-9);
    EXPECT_EQ(w["knobs"][1]["key"], "dram.channels");
    // Not a tie: channels 10 points ahead stay first.
    auto far = [](const SimConfig& x) {
        return 1000.0 / (x.dram.channels == 4 ? 1.25 : 1.0) / (x.l2.size_kib == 2048 ? 1.14 : 1.0);
    };
    WeighInputs in2{c, nlohmann::json::array(), far, far(c), "", {}};
    in2.dram_bytes = bytes;
    EXPECT_EQ(weigh_knobs(in2)["knobs"][0]["key"], "dram.channels");
}

TEST(Verdict, TechniquesAddAreaOnlyWhenOn) {
    SimConfig c;
    c.traversal.ray_contexts = 16;
    const TechniqueArea plain = technique_area(c, nlohmann::json::array());
    EXPECT_EQ(plain.logic_mm2.count("context_scheduler"), 1u);  // MIMD's scheduler over its contexts
    for (const char* b : {"node_decoder", "leaf_decoder", "simt_control", "sort_stage", "prefetcher"})
        EXPECT_EQ(plain.logic_mm2.count(b), 0u) << b;
    const nlohmann::json built = structure_blocks("cwbvh8", "", true);
    const TechniqueArea quant = technique_area(c, built);
    EXPECT_GT(quant.logic_mm2.at("node_decoder"), 0.0);
    EXPECT_GT(quant.sram_bytes.at("leaf_decoder"), 0.0);
    c.traversal.model = "simt";
    c.dispatch.sort = RaySort::morton;
    c.treelets.prefetch = true;
    const TechniqueArea more = technique_area(c, nlohmann::json::array());
    EXPECT_GT(more.logic_mm2.at("simt_control"), 0.0);
    EXPECT_EQ(more.logic_mm2.count("context_scheduler"), 0u);
    EXPECT_GT(more.logic_mm2.at("sort_stage"), 0.0);
    EXPECT_GT(more.logic_mm2.at("prefetcher"), 0.0);
    // More warps cost more scheduler; more contexts cost a MIMD unit more.
    SimConfig wide = c;
    wide.traversal.ray_contexts = 64;
    EXPECT_GT(technique_area(wide, nlohmann::json::array()).logic_mm2.at("simt_control"), more.logic_mm2.at("simt_control"));
}

TEST(Verdict, KnobsSayWhichResourcesTheyRelax) {
    SimConfig c;
    const auto has = [](const std::vector<std::string>& v, const char* x) {
        return std::find(v.begin(), v.end(), x) != v.end();
    };
    EXPECT_TRUE(has(knob_relaxes(c, "traversal.units"), "l1_mshrs"));
    EXPECT_TRUE(has(knob_relaxes(c, "traversal.units"), "latency"));
    EXPECT_FALSE(has(knob_relaxes(c, "traversal.units"), "dram"));
    EXPECT_TRUE(has(knob_relaxes(c, "l2.size_kib"), "dram"));  // the traffic it removes
    EXPECT_TRUE(has(knob_relaxes(c, "box.width"), "box"));
    EXPECT_EQ(resource_label("l2_banks"), "L2 banks");
    EXPECT_EQ(resource_label("box"), "box pipelines");
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
