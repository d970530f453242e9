// A unit kind registered from a test-only folder (probe_unit.cpp) runs end to end through the
// harness: its section is read and written like any block's, the resolution step applies the
// rules to its declared needs, its stats block is checked, and every hit matches the reference.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "sim/config/config.h"
#include "sim/harness/simulate.h"
#include "sim/resolve/resolve.h"
#include "traces/tracer/tracer.h"
#include "tests/cpp/error_of.h"
#include "tests/cpp/process_temp_dir.h"

namespace rtsim {
namespace {

namespace fs = std::filesystem;

TEST(ProbeUnitKind, IsAChoiceWithItsOwnSection) {
    const nlohmann::json schema = config_schema();
    const nlohmann::json& traversal = schema["traversal"]["fields"];
    const auto& choices = traversal["model"]["choices"];
    EXPECT_NE(std::find(choices.begin(), choices.end(), "probe"), choices.end());
    ASSERT_TRUE(traversal.contains("probe"));
    EXPECT_EQ(traversal["probe"]["fields"]["tag"]["default"], 7);
    SimConfig c;
    config_set(c, "traversal.model=probe");
    config_set(c, "traversal.probe.tag=42");
    EXPECT_EQ(config_to_json(c)["traversal"]["probe"]["tag"], 42);
    EXPECT_NE(test::error_of([&] { config_set(c, "traversal.probe.tag=1001"); validate(c); }).find("traversal.probe.tag"),
              std::string::npos);
}

TEST(ProbeUnitKind, ItsNeedsAreMatchedByTheRules) {
    SimConfig c;
    config_set(c, "traversal.model=probe");
    config_set(c, "treelets.enabled=true");
    const std::string msg = test::error_of([&] { resolve_run(c, structure_facts("bvh2")); });
    EXPECT_NE(msg.find("treelets.enabled"), std::string::npos) << msg;
    EXPECT_NE(msg.find("traversal.model 'probe'"), std::string::npos) << msg;
}

TEST(ProbeUnitKind, RunsEndToEndWithEveryHitChecked) {
    const fs::path dir = test::process_temp_dir("probe_kind");
    TraceOptions t;
    t.scene = "cornell";
    t.out_dir = (dir / "trace").string();
    t.width = 16;
    t.height = 12;
    t.threads = 1;
    trace_scene(t);
    SimOptions o;
    o.trace = t.out_dir;
    o.out_dir = (dir / "run").string();
    config_set(o.config, "traversal.model=probe");
    config_set(o.config, "traversal.probe.tag=42");
    o.verdict = false;
    const SimOutcome r = run_simulation(o);
    EXPECT_EQ(r.exit_code, 0);
    const nlohmann::json& s = r.stats["summary"];
    EXPECT_GT(s["rays"].get<uint64_t>(), 0u);
    EXPECT_EQ(s["hit_mismatches"], 0);
    EXPECT_EQ(s["work_mismatches"], 0);
    for (const auto& unit : r.stats["model"]["units"]) EXPECT_EQ(unit["probe_tag"], 42);
    std::ifstream resolved(dir / "run" / "config.resolved.json");
    EXPECT_EQ(nlohmann::json::parse(resolved)["traversal"]["probe"]["tag"], 42);
}

}  // namespace
}  // namespace rtsim
