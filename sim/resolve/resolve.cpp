#include "sim/resolve/resolve.h"

#include "sim/harness/memory_estimate.h"

#include "traces/common/error.h"
#include "traces/common/files.h"

namespace rtsim {

using nlohmann::json;

json RunSetup::to_json() const {
    json d = json::array(), u = json::array();
    for (const DerivedField& f : derived) d.push_back({{"key", f.key}, {"value", f.value}, {"why", f.why}});
    for (const Unused& x : unused) u.push_back({{"key", x.asks}, {"why", x.why}});
    return {{"derived", d}, {"unused", u}};
}

namespace {

/// The fields a config may leave to the run, filled from the unit kind and the structure.
void derive_fields(RunSetup& s) {
    TraversalConfig& t = s.config.traversal;
    if (t.ray_contexts == 0) {
        t.ray_contexts = t.contexts();
        const uint32_t g = t.group_size();
        s.derived.push_back({"traversal.ray_contexts", t.ray_contexts,
                             g > 1 ? std::to_string(kDefaultRayContexts) + " rounded up to whole " + s.unit->group_name +
                                         "s of " + std::to_string(g) + " rays (traversal.model " + t.model + ")"
                                   : std::to_string(kDefaultRayContexts) + " per unit (traversal.model " + t.model + ")"});
    }
    if (t.stack_entry_bytes == 0) {
        t.stack_entry_bytes = s.structure.stack_entry_bytes;
        s.derived.push_back({"traversal.stack_entry_bytes", t.stack_entry_bytes,
                             "the stack entry of " + s.structure.name()});
    }
}

}  // namespace

RunSetup resolve_run(const SimConfig& config, const StructureFacts& structure) {
    validate(config);  // ranges and each block's own field rules
    RunSetup s;
    s.config = config;
    s.structure = structure;
    s.level = level_capabilities(config);
    s.unit = &unit_kind(config.traversal.model);
    const RunFacts facts{s.config, s.structure, *s.unit, s.level};
    for (const Rule& r : run_rules())
        if (r.active(facts) && !r.met(facts)) throw Error(refusal(r, facts));
    s.unused = unused_settings(facts);
    derive_fields(s);
    const TraversalConfig& t = s.config.traversal;
    s.step.mailbox_entries = s.config.mailbox.entries;
    s.step.short_stack_entries = t.stack_overflow == StackOverflow::restart_trail ? t.stack_entries : 0;
    s.step.box_precision_bits = t.box_precision_bits;
    s.step.quantized_box_tests = t.quantized_boxes;
    s.step.anyhit_order = t.anyhit_order;
    s.step.traced_anyhit_order = s.structure.traced_anyhit_order;
    if (s.unit->needs.packet_kernel) s.packet_reference = s.unit->packet_reference(t);
    return s;
}

json check_runs(const std::string& path) {
    const json list = json::parse(read_small_file(path, "run list", 256u << 20), nullptr, false);
    require(list.is_array(), path + ": not a JSON list of runs");
    json out = json::array();
    for (const json& run : list) {
        json r = {{"ok", false}, {"error", nullptr}, {"resolved", nullptr}};
        try {
            require(run.is_object(), "a run must be an object {config, accel, blas_kind, compressed_leaves}");
            const SimConfig c = config_from_json(run.value("config", json::object()));
            const StructureFacts f = structure_facts(run.value("accel", "bvh2"), run.value("blas_kind", ""),
                                                     run.value("compressed_leaves", false));
            const RunSetup s = resolve_run(c, f);
            // The model's own memory estimate, as a run makes it before elaborating (here
            // without the structure's image, which no trace holds yet).
            check_sim_memory(s.config, 0, "the run");
            r["ok"] = true;
            r["resolved"] = s.to_json();
        } catch (const Error& e) {
            r["error"] = e.what();
        }
        out.push_back(r);
    }
    return out;
}

}  // namespace rtsim
