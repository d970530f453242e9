// The table of what composes with what (`rtsim capabilities`, docs/capabilities.md): the rules,
// the structures' capabilities, the unit kinds' needs, the levels', and a matrix of techniques x
// unit kinds x structures and x levels, each cell resolved by resolve_run itself, so the table
// cannot disagree with what a run does.
#include <sstream>

#include "sim/resolve/resolve.h"
#include "traces/accel/accel.h"
#include "traces/common/data_kind.h"
#include "traces/common/ray.h"
#include "traces/common/error.h"

namespace rtsim {

using nlohmann::json;

namespace {

const char* side_text(RuleSide s) {
    switch (s) {
        case RuleSide::structure: return "structure";
        case RuleSide::unit: return "unit kind";
        case RuleSide::level: return "level";
        case RuleSide::technique: return "technique";
    }
    return "";
}

/// The techniques the matrix tries, each as the assignments that switch it on.
const std::vector<std::pair<std::string, std::vector<std::string>>>& techniques() {
    static const std::vector<std::pair<std::string, std::vector<std::string>>> t = {
        {"(none)", {}},
        {"treelets", {"treelets.enabled=true"}},
        {"treelet prefetching", {"treelets.enabled=true", "treelets.prefetch=true"}},
        {"prefetching, no queues", {"treelets.prefetch=true"}},
        {"restart trail", {"traversal.stack_overflow=restart_trail"}},
        {"8-bit boxes", {"traversal.box_precision_bits=7"}},
        {"any-hit largest box first", {"traversal.anyhit_order=largest_box"}},
        {"mailbox", {"mailbox.entries=8"}},
        {"stack prefetching (TTP)", {"traversal.stack_prefetch=2"}},
        {"cooperative lanes (CoopRT)", {"traversal.simt.cooperative=true"}},
        {"quantised boxes (AQB8)", {"traversal.quantized_boxes=true"}},
        {"ray sorting", {"dispatch.sort=morton"}},
        {"20% sampling", {"sampling.fraction=0.2"}},
    };
    return t;
}

std::vector<StructureFacts> structures() {
    std::vector<StructureFacts> out;
    for (const AccelKindInfo& k : accel_kinds()) out.push_back(structure_facts(k.name));
    out.push_back(structure_facts("two_level", "bvh2"));
    return out;
}

/// "yes", or the id of the rule that refuses.
std::string cell(const std::string& unit, const std::vector<std::string>& sets, const StructureFacts& s,
                 const std::string& level) {
    SimConfig c;
    config_set(c, "traversal.model=" + unit);
    config_set(c, "fidelity=" + level);
    for (const std::string& a : sets) config_set(c, a);
    try {
        return resolve_run(c, s).unused.empty() ? "yes" : "no effect";
    } catch (const Error& e) {
        // Two rules may need the same thing for the same reason; what asks tells them apart.
        const std::string what = e.what();
        for (const Rule& r : run_rules())
            if (what.find(r.asks) != std::string::npos && what.find(r.needs) != std::string::npos &&
                what.find(r.reason) != std::string::npos)
                return r.id;
        return "no";
    }
}

}  // namespace

json declared_names() {
    json rays = json::array(), data = json::array(), ops = json::array(), units = json::array(),
         accels = json::array(), anyhit = json::array();
    for (int k = 0; k < kRayKindCount; ++k) rays.push_back(ray_kind_name(RayKind(k)));
    for (const DataKindInfo& d : kDataKinds) data.push_back(d.name);
    for (const char* op : kOpKindNames) ops.push_back(op);
    for (const UnitKind* k : unit_kinds()) units.push_back(k->name);
    for (const AccelKindInfo& a : accel_kinds()) accels.push_back(a.name);
    for (const char* order : kAnyHitOrderNames) anyhit.push_back(order);
    return {{"ray_kinds", rays},       {"data_kinds", data},     {"op_kinds", ops},
            {"unit_kinds", units},     {"accel_kinds", accels}, {"anyhit_orders", anyhit}};
}

json capability_table() {
    json rules = json::array();
    for (const Rule& r : run_rules())
        rules.push_back({{"id", r.id},
                         {"asks", r.asks},
                         {"side", side_text(r.side)},
                         {"needs", r.needs},
                         {"reason", r.reason},
                         {"change", r.change},
                         {"example", {{"accel", r.example_accel}, {"set", r.example_set}}}});
    json kinds = json::array();
    for (const UnitKind* k : unit_kinds()) {
        json knobs = json::array();
        for (const UnitKnob& n : k->knobs) knobs.push_back(n.key);
        kinds.push_back({{"name", k->name},
                         {"summary", k->summary},
                         {"group", k->group_name},
                         {"needs",
                          {{"packet_kernel", k->needs.packet_kernel},
                           {"lock_step", k->needs.lock_step},
                           {"per_ray_stack", k->needs.per_ray_stack},
                           {"treelet_queues", k->needs.treelet_queues},
                           {"treelet_prefetch", k->needs.treelet_prefetch}}},
                         {"knobs", knobs}});
    }
    json structs = json::array();
    for (const StructureFacts& s : structures())
        structs.push_back({{"name", s.blas_kind.empty() ? s.kind : s.kind + " (" + s.blas_kind + ")"},
                           {"capabilities", s.caps.to_json()}});
    json levels = json::array();
    for (const std::string name : {"functional", "analytic", "analytic_functional", "approx", "detailed"}) {
        SimConfig c;
        config_set(c, "fidelity=" + name.substr(0, name.find('_')));
        if (name == "analytic_functional") config_set(c, "analytic.caches=functional");
        const LevelCapabilities l = level_capabilities(c);
        levels.push_back({{"name", l.name},
                          {"timed", l.timed},
                          {"lock_step", l.lock_step},
                          {"group_profiles", l.group_profiles},
                          {"treelets", l.treelets},
                          {"frames", l.frames},
                          {"steps_rays", l.steps_rays}});
    }
    // Techniques x unit kinds x structures at the default level; x levels on bvh2.
    json by_structure = json::array(), by_level = json::array(), techs = json::array();
    for (const auto& [name, sets] : techniques()) techs.push_back({{"name", name}, {"set", sets}});
    const std::vector<StructureFacts> all = structures();
    for (const UnitKind* k : unit_kinds())
        for (const auto& [name, sets] : techniques()) {
            json row = {{"unit", k->name}, {"technique", name}, {"cells", json::object()}};
            for (const StructureFacts& s : all)
                row["cells"][s.blas_kind.empty() ? s.kind : s.kind] = cell(k->name, sets, s, "approx");
            by_structure.push_back(row);
            json lrow = {{"unit", k->name}, {"technique", name}, {"cells", json::object()}};
            for (const std::string level : {"functional", "analytic", "approx", "detailed"})
                lrow["cells"][level] = cell(k->name, sets, structure_facts("bvh2"), level);
            by_level.push_back(lrow);
        }
    return {{"rules", rules},
            {"unit_kinds", kinds},
            {"structures", structs},
            {"levels", levels},
            {"techniques", techs},
            {"by_structure", by_structure},
            {"by_level", by_level}};
}

std::string capability_markdown() {
    const json t = capability_table();
    std::ostringstream md;
    auto yes = [](const json& b) { return b.get<bool>() ? "yes" : "-"; };
    md << "### Structures and what they offer\n\n| structure | packet kernel | restart trail | reduced-precision boxes | "
          "quantised boxes | any-hit order | mailbox | compressed leaves | treelet partition | stack addresses | stack entry (bytes) |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const json& s : t["structures"]) {
        const json& c = s["capabilities"];
        md << "| " << s["name"].get<std::string>() << " | " << yes(c["packet_kernel"]) << " | "
           << yes(c["restart_trail"]) << " | " << yes(c["reduced_precision_boxes"]) << " | " << yes(c["quantized_boxes"])
           << " | " << yes(c["anyhit_order"])
           << " | " << yes(c["mailbox"])
           << " | " << yes(c["compressed_leaves"]) << " | " << yes(c["treelet_partition"]) << " | "
           << yes(c["stack_addresses"]) << " | " << c["stack_entry_bytes"].get<uint32_t>() << " |\n";
    }
    md << "\n### Unit kinds and what they need\n\n| kind | what it models | packet kernel | lock-step groups | own "
          "stack per ray | treelet queues | treelet prefetches | its knobs |\n|---|---|---|---|---|---|---|---|\n";
    for (const json& k : t["unit_kinds"]) {
        std::string knobs;
        for (const json& n : k["knobs"]) knobs += (knobs.empty() ? "`" : ", `") + n.get<std::string>() + "`";
        md << "| `" << k["name"].get<std::string>() << "` | " << k["summary"].get<std::string>() << " | "
           << yes(k["needs"]["packet_kernel"]) << " | " << yes(k["needs"]["lock_step"]) << " | "
           << yes(k["needs"]["per_ray_stack"]) << " | " << yes(k["needs"]["treelet_queues"]) << " | "
           << yes(k["needs"]["treelet_prefetch"]) << " | "
           << (knobs.empty() ? "-" : knobs) << " |\n";
    }
    md << "\n### Levels and what they cost\n\n| level | timed | lock-step groups | treelet queues | frames | steps "
          "the rays |\n|---|---|---|---|---|---|\n";
    for (const json& l : t["levels"])
        md << "| " << l["name"].get<std::string>() << " | " << yes(l["timed"]) << " | "
           << (l["lock_step"].get<bool>() ? "yes" : l["group_profiles"].get<bool>() ? "from a group profile" : "-")
           << " | " << yes(l["treelets"]) << " | " << yes(l["frames"]) << " | " << yes(l["steps_rays"]) << " |\n";
    md << "\n### The rules\n\nEach refusal a run can meet, from the one resolution step; the example is a run it "
          "refuses (the tests run every one through the CLI).\n\n| rule | asks | needs | of the | why | change |\n"
          "|---|---|---|---|---|---|\n";
    for (const json& r : t["rules"])
        md << "| `" << r["id"].get<std::string>() << "` | " << r["asks"].get<std::string>() << " | "
           << r["needs"].get<std::string>() << " | " << r["side"].get<std::string>() << " | "
           << r["reason"].get<std::string>() << " | " << r["change"].get<std::string>() << " |\n";
    auto matrix = [&](const char* title, const json& rows) {
        md << "\n### " << title << "\n\n| unit kind | technique |";
        const json& first = rows[0]["cells"];
        for (auto it = first.begin(); it != first.end(); ++it) md << " " << it.key() << " |";
        md << "\n|---|---|";
        for (size_t i = 0; i < first.size(); ++i) md << "---|";
        md << "\n";
        for (const json& row : rows) {
            md << "| " << row["unit"].get<std::string>() << " | " << row["technique"].get<std::string>() << " |";
            for (auto it = row["cells"].begin(); it != row["cells"].end(); ++it) {
                const std::string v = it.value();
                md << " " << (v == "yes" || v == "no effect" ? v : "`" + v + "`") << " |";
            }
            md << "\n";
        }
    };
    md << "\n### The techniques the matrices switch on\n\n| technique | config |\n|---|---|\n";
    for (const json& tech : t["techniques"]) {
        std::string sets;
        for (const json& a : tech["set"]) sets += (sets.empty() ? "`" : ", `") + a.get<std::string>() + "`";
        md << "| " << tech["name"].get<std::string>() << " | " << (sets.empty() ? "-" : sets) << " |\n";
    }
    md << "\nEvery cell below is run on a tiny trace by `tests/python/test_composition_matrix.py`: a `yes` "
          "replays with 0 hit and 0 work mismatches, a rule's id exits 2 with the rule's words.\n";
    matrix("What composes, by structure (fidelity approx)", t["by_structure"]);
    matrix("What composes, by level (bvh2)", t["by_level"]);
    return md.str();
}

}  // namespace rtsim
