#include "sim/report/verdict_knobs.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "rtl_model/traversal/simt/simt_config.h"
#include "sim/report/energy_area.h"
#include "sim/report/technique_cost.h"
#include "traces/accel/accel.h"
#include "traces/common/error.h"

namespace rtsim {

using nlohmann::json;

namespace {

/// A pair is a co-limit when its joint gain is much more than either alone: at least 1.5x the
/// better single gain plus five points (2.06x jointly against 1.07x and 1.12x alone is one).
constexpr double kCoLimitFactor = 1.5, kCoLimitMargin = 0.05;
/// Knobs whose pairs are tried: the best this many by estimated gain (every estimable knob of a
/// default config: a co-limit's knobs gain little alone, so a short list by gain would miss it).
constexpr size_t kPairPool = 24;
/// Estimates this close are within the analytic level's error of each other (the verdict's text
/// says so); of two such, the one that also cuts DRAM traffic by this share more is named first:
/// it pays the same and saves energy (a larger cache against more channels).
constexpr double kTie = 0.03, kTieSaving = 0.05;

void add(std::vector<Knob>* out, Relaxation r, const std::string& resource, bool estimable = true) {
    if (!r.key.empty()) out->push_back({std::move(r), resource, estimable});
}

/// A pipeline kind's relaxation: more shared pipelines, a shorter initiation interval, or wider.
Relaxation pipeline_relaxation(const SimConfig& c, OpKind kind) {
    const PipelineConfig& p = c.pipeline(kind);
    const std::string base = std::string(op_kind_name(kind)) + ".";
    if (p.shared()) return doubled(c, base + "shared_count");
    if (p.initiation_interval > 1) return halved(c, base + "initiation_interval");
    return doubled(c, base + "width");
}

void treelet_knobs(const SimConfig& c, std::vector<Knob>* out) {
    // The analytic level has no ray buffer: these are measured, never estimated.
    add(out, doubled(c, "treelets.admit_outstanding"), "admission", false);
    if (c.treelets.max_rays_in_flight > 0) add(out, doubled(c, "treelets.max_rays_in_flight"), "admission", false);
    add(out, doubled(c, "treelets.buffer_kib"), "ray_buffer", false);
    add(out, doubled(c, "treelets.bytes_per_cycle"), "ray_buffer", false);
    for (size_t i = 0; i < kTreeletPolicyChoices.names.size(); ++i)
        if (TreeletPolicy(i) != c.treelets.policy)
            add(out, {"treelets.policy", kTreeletPolicyChoices.name(c.treelets.policy), kTreeletPolicyChoices.names[i]},
                "treelet_scheduling", false);
}

double num_or(const json& j, double fallback) { return j.is_number() ? j.get<double>() : fallback; }

/// Best first: by estimated gain where there is one, else by the share of context cycles that
/// point at the knob's resource.
void rank(json& knobs) {
    std::stable_sort(knobs.begin(), knobs.end(), [](const json& a, const json& b) {
        const bool ea = a["speedup"].is_number(), eb = b["speedup"].is_number();
        if (ea != eb) return ea;
        if (ea && a["speedup"] != b["speedup"]) return a["speedup"].get<double>() > b["speedup"].get<double>();
        return a["evidence"].get<double>() > b["evidence"].get<double>();
    });
}

json first(const json& list, size_t n) {
    json out = json::array();
    for (size_t i = 0; i < list.size() && i < n; ++i) out.push_back(list[i]);
    return out;
}

/// Knobs that keep the speed and save area: pipelines a kind's private copies leave idle, shared
/// by the units instead (a pool of `shared_count`). Curved primitives' and alpha tests' pipelines
/// are the usual ones: few rays test them, and a pipeline per unit is mostly idle.
void sharing_knobs(const SimConfig& c, const std::vector<OpKind>& ops, std::vector<Knob>* out) {
    for (OpKind kind : ops) {
        const PipelineConfig& p = c.pipeline(kind);
        if (p.shared() || p.shared_count >= c.traversal.units) continue;
        add(out, {std::string(op_kind_name(kind)) + ".sharing", "private", "shared"}, op_kind_name(kind));
    }
}

/// Within the estimate's error of the run's speed and smaller: the three that save most area.
constexpr double kSameSpeed = 0.98;

json area_savers(const json& knobs) {
    json out = json::array();
    for (const json& k : knobs)
        if (k["added_mm2"].is_number() && k["added_mm2"].get<double>() < -1e-9 && k["speedup"].is_number() &&
            k["speedup"].get<double>() >= kSameSpeed)
            out.push_back(k);
    std::stable_sort(out.begin(), out.end(), [](const json& a, const json& b) {
        return a["added_mm2"].get<double>() < b["added_mm2"].get<double>();
    });
    return first(out, 3);
}

/// The three best gains per added mm^2 (knobs the area model prices, that gain at all).
json per_area(const json& knobs) {
    json out = json::array();
    for (const json& k : knobs)
        if (k["gain_per_mm2"].is_number() && num_or(k["speedup"], 1.0) > 1.005) out.push_back(k);
    std::stable_sort(out.begin(), out.end(), [](const json& a, const json& b) {
        return a["gain_per_mm2"].get<double>() > b["gain_per_mm2"].get<double>();
    });
    return first(out, 3);
}

Relaxation relaxation_of(const json& k) { return {k["key"].get<std::string>(), k["from"], k["to"]}; }

/// Pairs of the best estimated knobs whose joint gain is much more than either alone.
json co_limits(const WeighInputs& in, const json& knobs) {
    std::vector<json> pool;
    for (const json& k : knobs)
        if (k["speedup"].is_number() && pool.size() < kPairPool) pool.push_back(k);
    json out = json::array();
    for (size_t i = 0; i < pool.size(); ++i)
        for (size_t j = i + 1; j < pool.size(); ++j) {
            if (pool[i]["key"] == pool[j]["key"]) continue;
            double joint;
            try {
                const SimConfig both = relaxed_config(in.config, {relaxation_of(pool[i]), relaxation_of(pool[j])});
                joint = in.base_cycles / in.cycles(both);
            } catch (const Error&) {
                continue;
            }
            const double a = pool[i]["speedup"].get<double>(), b = pool[j]["speedup"].get<double>();
            if (joint - 1.0 < kCoLimitFactor * (std::max(a, b) - 1.0) + kCoLimitMargin) continue;
            out.push_back({{"keys", {pool[i]["key"], pool[j]["key"]}},
                           {"sets", {pool[i]["key"].get<std::string>() + "=" + pool[i]["to"].dump(),
                                     pool[j]["key"].get<std::string>() + "=" + pool[j]["to"].dump()}},
                           {"resources", {pool[i]["resource"], pool[j]["resource"]}},
                           {"joint", joint},
                           {"alone", {a, b}}});
        }
    std::stable_sort(out.begin(), out.end(),
                     [](const json& a, const json& b) { return a["joint"].get<double>() > b["joint"].get<double>(); });
    return first(out, 3);
}

}  // namespace

std::string value_text(const json& value) { return value.is_string() ? value.get<std::string>() : value.dump(); }

Relaxation doubled(const SimConfig& c, const std::string& key) {
    const ConfigField f = config_field(c, key);
    const double value = f.value.get<double>();
    if (value <= 0 || value * 2 > f.max) return {};
    return {key, f.value, json(f.value.get<uint64_t>() * 2)};
}

Relaxation halved(const SimConfig& c, const std::string& key) {
    const ConfigField f = config_field(c, key);
    const uint64_t value = f.value.get<uint64_t>();
    if (value / 2 < f.min || value < 2) return {};
    return {key, f.value, json(value / 2)};
}

std::vector<Knob> every_knob(const SimConfig& c, const std::vector<OpKind>& ops, const std::vector<KindKnob>& kind_knobs) {
    std::vector<Knob> out;
    add(&out, doubled(c, "traversal.units"), "units");
    add(&out, doubled(c, "traversal.ray_contexts"), "latency");
    for (OpKind kind : ops) add(&out, pipeline_relaxation(c, kind), op_kind_name(kind));
    add(&out, halved(c, "traversal.issue_cycles"), "scheduler");
    if (!c.ideal_memory) {
        add(&out, doubled(c, "l1.size_kib"), "l1_capacity");
        add(&out, doubled(c, "l2.size_kib"), "l2_capacity");
        add(&out, doubled(c, "l1.banks"), "l1_banks");
        add(&out, doubled(c, "l2.banks"), "l2_banks");
        add(&out, doubled(c, "l1.mshrs"), "l1_mshrs");
        add(&out, doubled(c, "l2.mshrs"), "l2_mshrs");
        add(&out, doubled(c, "dram.channels"), "dram");
    }
    add(&out, doubled(c, "traversal.stack_entries"), "stack");
    for (const KindKnob& k : kind_knobs)
        add(&out, k.halve ? halved(c, k.key) : doubled(c, k.key), k.resource, k.estimated);
    sharing_knobs(c, ops, &out);
    if (c.treelets.enabled) treelet_knobs(c, &out);
    return out;
}

namespace {

void structural(std::vector<Knob>* out, Relaxation r, const std::string& resource, bool trace = false) {
    if (r.key.empty()) return;
    Knob k{std::move(r), resource, false};
    k.structural = true;
    k.trace = trace;
    out->push_back(std::move(k));
}

}  // namespace

std::vector<Knob> structural_knobs(const SimConfig& c, const StructureTraits& st) {
    std::vector<Knob> out;
    for (const StructureAlternative& alt : structure_alternatives(st.kind, st.compressed_leaves, st.curved)) {
        if (alt.key == "accel") structural(&out, {"accel", st.kind, alt.value}, "structure", true);
        else structural(&out, {alt.key, false, true}, "structure", true);
    }
    if (c.treelets.enabled) structural(&out, {"treelets.enabled", true, false}, "treelets");
    else if (st.treelet_partition)
        structural(&out, {"treelets.enabled", false, true}, "treelets");
    const std::string model = c.traversal.model == "mimd" ? "simt" : "mimd";
    structural(&out, {"traversal.model", c.traversal.model, model}, "execution_model");
    // The ray buffer reorders rays itself: sorting is refused with treelet scheduling.
    if (c.treelets.enabled) {
    } else if (c.dispatch.sort == RaySort::none) structural(&out, {"dispatch.sort", "none", "morton"}, "ray_order");
    else structural(&out, {"dispatch.sort", kRaySortChoices.name(c.dispatch.sort), "none"}, "ray_order");
    if (!c.ideal_memory && st.treelet_partition)
        structural(&out, {"treelets.prefetch", c.treelets.prefetch, !c.treelets.prefetch}, "prefetch");
    // The newest RT-unit techniques, where the design can take them: stack-driven prefetching
    // (TTP) on per-ray stacks that hold addresses, cooperative lanes (CoopRT) on warps, an integer
    // box pipeline (AQB8) on quantised nodes.
    const UnitKind& unit = c.traversal.kind();
    if (!c.ideal_memory && st.stack_addresses)
        structural(&out, {"traversal.stack_prefetch", c.traversal.stack_prefetch, c.traversal.stack_prefetch ? 0 : 2},
                   "latency");
    if (unit.name == "simt") {
        const bool coop = c.traversal.kinds.of<SimtConfig>("simt").cooperative;
        structural(&out, {"traversal.simt.cooperative", coop, !coop}, "divergence");
    }
    if (st.quantized_boxes && unit.needs.per_ray_stack && c.traversal.box_precision_bits == 0)
        structural(&out, {"traversal.quantized_boxes", c.traversal.quantized_boxes, !c.traversal.quantized_boxes}, "box");
    // An animated trace's frames rebuild, refit or choose (traces/accel/two_level/frame_policy.h):
    // another policy is another trace.
    if (!st.frame_policy.empty())
        for (const char* policy : {"rebuild", "refit", "adaptive"})
            if (st.frame_policy != policy) structural(&out, {"frame_policy", st.frame_policy, policy}, "build", true);
    return out;
}

std::string measure_command(const Knob& k, const StructureTraits& st) {
    const std::string trace = st.trace.empty() ? "TRACE" : st.trace;
    const std::string run = st.run.empty() ? std::string("RUN") : st.run;
    const std::string to = value_text(k.relax.to);
    if (!k.trace)
        return "rtsim simulate " + trace + " -o NEW_RUN --config " + run + "/config.resolved.json --set " + setting_text(k.relax);
    // Another structure's trace takes the config as given (resolved afresh against it: its stack
    // entries differ). Traced beside the run's already (rtsim trace --alternatives): simulate it.
    const std::string config = run + "/config.given.json";
    const std::filesystem::path beside =
        std::filesystem::path(trace).parent_path() / structure_alternative_dir({k.relax.key, to}) / "trace.rtt";
    std::error_code missing;
    if (k.relax.key != "frame_policy" && !st.trace.empty() && std::filesystem::exists(beside, missing))
        return "rtsim simulate " + beside.string() + " -o NEW_RUN --config " + config;
    const std::string option = k.relax.key == "accel"          ? "--accel " + to
                               : k.relax.key == "frame_policy" ? "--frame-policy " + to
                                                               : "--build-set compressed_leaves=true";
    return "rtsim trace SCENE -o NEW_TRACE " + option +
           " (the scene, workload and resolution of " + trace + "; its manifest.json lists them; or trace it with "
           "--alternatives), then rtsim simulate NEW_TRACE -o NEW_RUN --config " + config;
}

SimConfig relaxed_config(const SimConfig& config, const std::vector<Relaxation>& knobs) {
    SimConfig c = config;
    for (const Relaxation& r : knobs)
        config_set(c, setting_text(r));
    validate(c);
    return c;
}

json weigh_knobs(const WeighInputs& in) {
    std::vector<OpKind> ops;
    for (const json& b : in.instantiated)
        for (int k = 0; k < kOpKindCount; ++k)
            if (b.value("block", "") == op_kind_name(OpKind(k)) && b.value("instantiated", false))
                ops.push_back(OpKind(k));
    const double base_mm2 = area_total_mm2(in.config, in.instantiated);
    const double base_bytes = in.dram_bytes ? in.dram_bytes(in.config) : 0.0;
    json knobs = json::array();
    for (const Knob& k : every_knob(in.config, ops, in.kind_knobs)) {
        json j = {{"key", k.relax.key}, {"resource", k.resource}, {"from", k.relax.from}, {"to", k.relax.to},
                  {"speedup", nullptr}, {"added_mm2", nullptr}, {"gain_per_mm2", nullptr}};
        const auto e = in.evidence.find(k.resource);
        j["evidence"] = e == in.evidence.end() ? 0.0 : e->second;
        try {
            const SimConfig relaxed = relaxed_config(in.config, {k.relax});
            const double added = area_total_mm2(relaxed, in.instantiated) - base_mm2;
            j["added_mm2"] = added;
            if (!k.estimable || !in.not_covered.empty() || !in.cycles) {
                const bool machine = k.estimable && !in.not_covered.empty();
                j["why_not"] = machine ? in.not_covered : "the analytic level does not model it: measure it";
            } else {
                const double speedup = in.base_cycles / in.cycles(relaxed);
                j["speedup"] = speedup;
                if (added > 1e-9) j["gain_per_mm2"] = (speedup - 1.0) / added;
                if (in.dram_bytes && base_bytes > 0)
                    j["dram_saved_fraction"] = 1.0 - in.dram_bytes(relaxed) / base_bytes;
            }
        } catch (const Error& e) {
            j["why_not"] = e.what();
        }
        knobs.push_back(j);
    }
    rank(knobs);
    // A near tie goes to the knob that also removes DRAM traffic (same speed, less energy).
    if (knobs.size() > 1 && knobs[0]["speedup"].is_number() && knobs[1]["speedup"].is_number() &&
        knobs[1]["speedup"].get<double>() >= knobs[0]["speedup"].get<double>() - kTie &&
        knobs[1].value("dram_saved_fraction", 0.0) >= knobs[0].value("dram_saved_fraction", 0.0) + kTieSaving) {
        std::swap(knobs[0], knobs[1]);
        knobs[0]["tie_break"] = "within the estimate's error of " + knobs[1]["key"].get<std::string>() +
                                "'s gain, and it also removes DRAM traffic";
    }
    // The structural alternatives: another design, not a step of a resource. Each is priced and
    // comes with the command that measures it; the estimator estimates those the analytic level
    // can cost on an analysis of their own (another structure traced beside this one, another
    // execution model, treelets flipped), never on this design's analysis.
    json structural = json::array();
    for (const Knob& k : structural_knobs(in.config, in.structure)) {
        json j = {{"key", k.relax.key}, {"resource", k.resource}, {"from", k.relax.from}, {"to", k.relax.to},
                  {"speedup", nullptr}, {"added_mm2", nullptr}, {"gain_per_mm2", nullptr}, {"structural", true},
                  {"trace", k.trace}, {"measure", measure_command(k, in.structure)}};
        const auto e = in.evidence.find(k.resource);
        j["evidence"] = e == in.evidence.end() ? 0.0 : e->second;
        try {
            if (k.trace) {
                // The new structure's decoders (technique_cost.h) in place of this one's.
                StructureTraits next = in.structure;
                if (k.relax.key == "accel") next.kind = k.relax.to.get<std::string>();
                else if (k.relax.key == "compressed_leaves") next.compressed_leaves = true;
                json inst = json::array();
                for (const json& b : in.instantiated)
                    if (b.value("block", "") != "node_decoder" && b.value("block", "") != "leaf_decoder") inst.push_back(b);
                for (const json& b : structure_blocks(next.kind, next.blas_kind, next.compressed_leaves)) inst.push_back(b);
                j["added_mm2"] = area_total_mm2(in.config, inst) - base_mm2;
            } else {
                j["added_mm2"] = area_total_mm2(relaxed_config(in.config, {k.relax}), in.instantiated) - base_mm2;
            }
        } catch (const Error& e) {
            j["refused"] = e.what();
        }
        const StructuralEstimate est = in.structural && in.not_covered.empty() && !j.contains("refused")
                                         ? in.structural(k)
                                         : StructuralEstimate{0, "", in.not_covered.empty() ? "" : in.not_covered};
        if (est.speedup > 0) {
            j["speedup"] = est.speedup;
            j["estimated_by"] = est.method;
            if (j["added_mm2"].is_number() && j["added_mm2"].get<double>() > 1e-9)
                j["gain_per_mm2"] = (est.speedup - 1.0) / j["added_mm2"].get<double>();
        } else {
            j["why_not"] = "a structural change, not estimated" + (est.why_not.empty() ? std::string() : " (" + est.why_not + ")") +
                           ": measure it (" + j["measure"].get<std::string>() + ")";
        }
        structural.push_back(j);
    }
    rank(structural);
    return {{"knobs", knobs},
            {"structural", structural},
            {"top", first(knobs, 3)},
            {"top_per_mm2", per_area(knobs)},
            {"area_savers", area_savers(knobs)},
            {"co_limits", in.cycles && in.not_covered.empty() ? co_limits(in, knobs) : json::array()}};
}

}  // namespace rtsim
