#include "sim/report/verdict.h"

#include <cctype>
#include "sim/report/report_block.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>

#include "sim/report/verdict_estimator.h"
#include "traces/common/error.h"

namespace rtsim {

using nlohmann::json;

namespace {

/// Utilisation at which a resource counts as saturated rather than merely slow.
constexpr double kSaturated = 0.7;

/// The resources the verdict can name besides the pipelines: the name the analytic bounds and
/// stats use, what a person calls it and the utilisation that shows it busy (model.utilization;
/// "" if none). The knobs that relax them are declared once, in verdict_knobs.cpp.
struct ResourceInfo {
    const char* name;
    const char* label;
    const char* busy;
};

const std::vector<ResourceInfo>& resource_table() {
    static const std::vector<ResourceInfo> r = {
        {"l1_mshrs", "L1 MSHRs", "l1_mshrs"},
        {"l2_mshrs", "L2 MSHRs", "l2_mshrs"},
        {"dram", "DRAM bandwidth", "dram_bandwidth"},
        {"l1_banks", "L1 banks", "l1_banks"},
        {"l2_banks", "L2 banks", "l2_banks"},
        {"latency", "latency not hidden (memory and pipeline latency over too few ray contexts)", ""},
        {"scheduler", "the traversal units' schedulers (one step per issue_cycles)", ""},
        {"stack", "stack spills (spilled entries read back)", ""},
        {"ray_buffer", "the ray buffer SRAM", ""},
        {"workload", "the workload: too few rays to keep the machine busy (contexts idle)", ""},
        {"units", "too few traversal units", ""},
        {"l1_capacity", "L1 capacity (misses to the L2)", ""},
        {"l2_capacity", "L2 capacity (misses to DRAM)", ""},
        {"admission", "treelet admission (rays admitted into the ray buffer)", ""},
        {"treelet_scheduling", "treelet scheduling (which queue a free unit runs)", ""},
        {"divergence", "divergence (SIMT warp lanes, or packet rays, masked off while others step)", ""},
    };
    return r;
}

const ResourceInfo* find_resource(const std::string& name) {
    for (const ResourceInfo& r : resource_table())
        if (name == r.name) return &r;
    return nullptr;
}

/// The operation kind a resource names (its pipelines), if it names one.
bool op_kind_of(const std::string& resource, OpKind* kind) {
    for (int k = 0; k < kOpKindCount; ++k)
        if (resource == op_kind_name(OpKind(k))) return *kind = OpKind(k), true;
    return false;
}

std::string label_of(const std::string& resource) {
    const ResourceInfo* r = find_resource(resource);
    return r ? r->label : resource + " pipelines";  // an operation kind
}

/// The utilisation that shows a resource busy ("" if none).
std::string busy_of(const std::string& resource) {
    OpKind kind;
    if (op_kind_of(resource, &kind)) return std::string("pipe_") + op_kind_name(kind);
    const ResourceInfo* r = find_resource(resource);
    return r ? r->busy : "";
}

/// What a context waits for, in words, for each cycle use.
std::string waiting_for(const std::string& use) {
    static const std::map<std::string, std::string> w = {
        {"l1_mshr_full", "a free L1 MSHR"},  {"l2_mshr_full", "a free L2 MSHR"},
        {"dram", "data from DRAM"},          {"l2", "data from the L2"},
        {"l1_hit", "data from its L1"},      {"issue", "its unit's scheduler"},
        {"stack", "spilled stack entries"},  {"ray_buffer", "the ray buffer"},
        {"dispatch", "dispatch"},            {"starved", "a ray (starved)"},
        {"tail", "nothing: the workload had run out"}, {"idle_lane", "their warp (lanes masked off)"}};
    auto it = w.find(use);
    if (it != w.end()) return it->second;
    return "the " + use.substr(5) + " pipeline";  // pipe_<kind>
}

double utilization(const json& model, const std::string& name) {
    const json& u = model.value("utilization", json::object());
    return u.contains(name) ? u[name].value("mean", 0.0) : 0.0;
}

/// The resource behind a cycle use, refined by utilisation (saturated vs latency-bound).
std::string resource_of_use(const std::string& use, const json& model, std::string* busy_name) {
    auto saturated = [&](const char* name, const char* resource) {
        *busy_name = name;
        return utilization(model, name) >= kSaturated ? std::string(resource) : std::string("latency");
    };
    if (use == "l1_mshr_full") return *busy_name = "l1_mshrs", "l1_mshrs";
    if (use == "l2_mshr_full") return *busy_name = "l2_mshrs", "l2_mshrs";
    if (use == "dram") return saturated("dram_bandwidth", "dram");
    if (use == "l2") return saturated("l2_banks", "l2_banks");
    if (use == "l1_hit") return saturated("l1_banks", "l1_banks");
    if (use == "issue") return "scheduler";
    if (use == "stack" || use == "ray_buffer") return use;
    if (use == "starved" || use == "tail") return "workload";
    if (use == "idle_lane") return "divergence";
    if (use.rfind("pipe_", 0) == 0) {
        const std::string kind = use.substr(5);
        return saturated(use.c_str(), kind.c_str());
    }
    return "latency";  // dispatch
}

std::string percent(double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.0f%%", 100.0 * x);
    return buf;
}

/// Cycle uses of a timed run, largest first.
std::vector<std::pair<std::string, double>> uses_by_size(const json& model) {
    std::vector<std::pair<std::string, double>> uses;
    const json& fractions = model.at("cycle_accounting").at("fractions");
    for (auto it = fractions.begin(); it != fractions.end(); ++it) uses.push_back({it.key(), it.value().get<double>()});
    std::stable_sort(uses.begin(), uses.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
    return uses;
}

/// Whether each unit has its own `resource` (so more units relax it).
bool per_unit(const SimConfig& c, const std::string& resource) {
    OpKind kind;
    if (op_kind_of(resource, &kind)) return !c.pipeline(kind).shared();
    return resource == "latency" || resource == "scheduler" || resource == "l1_mshrs" || resource == "l1_banks";
}

/// What the evidence says of each resource: the share of context cycles that points at it, and
/// the largest use that does.
struct Evidence {
    std::map<std::string, double> share;
    std::map<std::string, std::string> use;
    std::string largest;  ///< the resource behind the largest use
    void add(const std::string& resource, const std::string& by, double fraction) {
        if (!use.count(resource)) use[resource] = by;
        share[resource] += fraction;
    }
};

/// The resources a timed run's cycle uses point at: each use's own (resource_of_use) and the
/// ones whose relaxation would shorten it (downstream of a full MSHR file, the saturated
/// resources its misses wait on; a bigger L2 for DRAM waits; more admission for starved
/// contexts in treelet mode; more units for a busy scheduler).
Evidence timed_evidence(const SimConfig& c, const json& model) {
    Evidence e;
    for (const auto& [use, fraction] : uses_by_size(model)) {
        std::string busy;
        const std::string r = resource_of_use(use, model, &busy);
        if (e.largest.empty()) e.largest = r;
        e.add(r == "workload" && use == "starved" && c.treelets.enabled ? "admission" : r, use, fraction);
        if (use == "l1_mshr_full" && utilization(model, "l2_mshrs") >= kSaturated) e.add("l2_mshrs", use, fraction);
        if ((use == "l1_mshr_full" || use == "l2_mshr_full") && utilization(model, "dram_bandwidth") >= kSaturated)
            e.add("dram", use, fraction);
        if (use == "dram" || use == "l2_mshr_full") e.add("l2_capacity", use, fraction / 2);
        if (use == "l2" || use == "l1_mshr_full") e.add("l1_capacity", use, fraction / 2);
        // More units relax every per-unit resource at once: contexts (latency hiding), the
        // scheduler, unshared pipelines, the L1's MSHRs and banks.
        if (per_unit(c, r)) e.add("units", use, fraction);
        if (use == "ray_buffer") e.add("treelet_scheduling", use, fraction / 2);
    }
    return e;
}

/// At the analytic level, the evidence is its own bounds: each bound's share of the largest.
Evidence analytic_evidence(const json& model, const std::string& binding) {
    Evidence e;
    e.largest = binding;
    const json& bounds = model.value("analytic", json::object()).value("bounds", json::object());
    double top = 0;
    for (auto it = bounds.begin(); it != bounds.end(); ++it)
        if (it->is_number()) top = std::max(top, it->get<double>());
    for (auto it = bounds.begin(); it != bounds.end(); ++it)
        if (it->is_number() && top > 0) e.add(it.key(), "bound", it->get<double>() / top);
    return e;
}

/// The evidence for `resource` in words: the use that points at it and the utilisation that
/// confirms it.
json evidence_for(const std::string& resource, const Evidence& e, const json& model, bool timed) {
    if (!timed) return {{"text", "the analytic level's binding bound is " + e.largest}};
    const auto it = e.use.find(resource);
    const std::string use = it != e.use.end() ? it->second : uses_by_size(model).front().first;
    const double fraction = model["cycle_accounting"]["fractions"].value(use, 0.0);
    json out = {{"use", use}, {"context_fraction", fraction}};
    // The largest use first, so a knob named for a smaller use does not hide where time went.
    const auto [top_use, top_fraction] = uses_by_size(model).front();
    std::string text = "contexts waited for " + waiting_for(top_use) + " " + percent(top_fraction) + " of their cycles";
    if (top_use != use) text += ", for " + waiting_for(use) + " " + percent(fraction);
    std::string busy;
    resource_of_use(use, model, &busy);
    if (busy.empty()) busy = busy_of(resource);
    if (!busy.empty() && model.contains("utilization")) {
        out["utilization"] = {{busy, utilization(model, busy)}};
        text += " (" + busy + " " + percent(utilization(model, busy)) + " busy)";
    }
    out["text"] = text;
    return out;
}

std::string gain(double speedup) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%+.0f%%", 100.0 * (speedup - 1.0));
    return buf;
}

std::string knob_text(const json& k) {
    std::string t = k["key"].get<std::string>() + " " + k["from"].dump() + " -> " + k["to"].dump();
    return k["speedup"].is_number() ? t + " " + gain(k["speedup"].get<double>()) : t;
}

/// The verdict's sentence: label, evidence, the best knob, the next two, co-limits, coverage.
std::string verdict_text(const json& v, const json& weighed, const std::string& not_covered) {
    std::string text = v["label"].get<std::string>() + ": " + v["evidence"].value("text", std::string());
    const json& relax = v["relax"];
    if (relax.is_null()) {
        text += "; no hardware knob relaxes it";
    } else if (relax["speedup"].is_number()) {
        text += "; " + knob_text(relax) + " estimated by the analytic level";
    } else if (not_covered.empty()) {
        text += "; " + knob_text(relax) + ": not estimated (" + relax.value("why_not", std::string("?")) + ")";
    } else {
        text += "; try " + knob_text(relax);
    }
    // Estimates this close are within the analytic level's error of each other: say so.
    const json& top = weighed["top"];
    if (top.size() > 1 && top[0]["speedup"].is_number() && top[1]["speedup"].is_number() &&
        top[0]["speedup"].get<double>() > 1.02 &&
        top[1]["speedup"].get<double>() >= top[0]["speedup"].get<double>() - 0.03)
        text += " (as good as " + top[1]["key"].get<std::string>() + " within the estimate's error: "
                "measure both with --check-verdict)";
    std::string next;
    for (const json& k : weighed["top"])
        if (relax.is_null() || k["key"] != relax["key"]) next += (next.empty() ? "" : ", ") + knob_text(k);
    if (!next.empty()) text += "; next: " + next;
    for (const json& co : weighed["co_limits"])
        text += "; co-limit: " + co["keys"][0].get<std::string>() + " and " + co["keys"][1].get<std::string>() +
                " together " + gain(co["joint"].get<double>()) + " (alone " + gain(co["alone"][0].get<double>()) +
                ", " + gain(co["alone"][1].get<double>()) + ")";
    if (!not_covered.empty()) text += "; " + not_covered;
    return text + " (analytic binding bound: " + v["analytic_binding"].get<std::string>() + ")";
}

/// Why the estimates do not describe this machine ("" when they do).
std::string coverage_gap(const SimConfig& c, const UnitTraits& unit) {
    if (!unit.estimate_as.empty()) {
        std::string stand_in = unit.estimate_as;
        for (char& ch : stand_in) ch = char(std::toupper(static_cast<unsigned char>(ch)));
        return "estimated for the " + stand_in + " machine with the same ray contexts (the analytic level has no "
               "lock-step warps: divergence is not in the estimates); measure them with --check-verdict";
    }
    return "";
}

}  // namespace

Relaxation relaxation_for(const std::string& resource, const SimConfig& c) {
    OpKind kind;
    const bool pipeline = op_kind_of(resource, &kind);
    for (const Knob& k : every_knob(c, pipeline ? std::vector<OpKind>{kind} : std::vector<OpKind>{}))
        if (k.resource == resource && (resource != "scheduler" || c.traversal.issue_cycles > 1)) return k.relax;
    if (resource == "scheduler") return doubled(c, "traversal.units");
    return {};  // the workload: no hardware knob
}

json judge(const VerdictContext& c) {
    if (c.config.fidelity == Fidelity::functional) return nullptr;
    const auto start = std::chrono::steady_clock::now();
    const VerdictEstimator estimator(c);
    const auto [base_cycles, analytic_binding] = estimator(c.config);
    const bool timed = c.config.fidelity != Fidelity::analytic;
    const Evidence evidence = timed ? timed_evidence(c.config, c.model) : analytic_evidence(c.model, analytic_binding);
    const std::string not_covered = coverage_gap(c.config, c.unit);
    WeighInputs in{c.config, c.instantiated, [&](const SimConfig& x) { return estimator(x).first; }, base_cycles,
                   not_covered, evidence.share, c.unit.knobs};
    const json weighed = weigh_knobs(in);
    // The binding resource: the best knob's when it buys 2% (or, unestimated, when the
    // evidence points at it); else the largest cycle use's.
    const json& best = weighed["knobs"].empty() ? json(nullptr) : weighed["knobs"][0];
    const bool best_pays = !best.is_null() && (best["speedup"].is_number() ? best["speedup"].get<double>() >= 1.02
                                                                             : best["evidence"].get<double>() > 0);
    const std::string binding = best_pays ? best["resource"].get<std::string>() : evidence.largest;
    json relax = best_pays ? best : json(nullptr);
    if (!best_pays)
        for (const json& k : weighed["knobs"])
            if (relax.is_null() && k["resource"] == binding) relax = k;
    json v = {{"binding", binding},
              {"label", label_of(binding)},
              {"evidence", evidence_for(binding, evidence, c.model, timed)},
              {"relax", relax},
              {"candidates", weighed["knobs"]},
              {"top", weighed["top"]},
              {"top_per_mm2", weighed["top_per_mm2"]},
              {"co_limits", weighed["co_limits"]},
              {"coverage", {{"estimated", not_covered.empty()},
                            {"why_not", not_covered.empty() ? json(nullptr) : json(not_covered)},
                            {"frames", c.frames}}},
              {"analytic_binding", analytic_binding},
              {"estimate",
               {{"method", estimator.method()},
                {"reused", estimator.reused()},
                {"base_cycles", base_cycles},
                {"wall_seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()}}}};
    // Two resources binding together: name both when relaxing the pair beats any single knob.
    const json& co = weighed["co_limits"].empty() ? json(nullptr) : weighed["co_limits"][0];
    const bool co_beats = !co.is_null() && best_pays && best["speedup"].is_number() &&
                          co["joint"].get<double>() > best["speedup"].get<double>();
    if (co_beats &&
        (co["resources"][0] == binding || co["resources"][1] == binding)) {
        const std::string other = co["resources"][co["resources"][0] == binding ? 1 : 0];
        v["label"] = label_of(binding) + " together with " + label_of(other) + " (a co-limit)";
    }
    v["text"] = verdict_text(v, weighed, not_covered);
    if (c.model.contains("shading")) v["frame"] = frame_knobs(c.model["shading"], weighed, c.config);
    return v;
}

json frame_knobs(const json& shading, const json& weighed, const SimConfig& config) {
    // What each side's knob buys the frame, by Amdahl over the frame's breakdown (docs/shading.md):
    // a part sped up by s leaves frame / (frame - part + part / s). The RT unit's best estimated
    // knob speeds traversal; doubling the shader cores or sorting by shader speeds shading (the
    // latter by the warps' divergence, the programs a sorted warp no longer serialises).
    const double frame = shading["frame_cycles"].get<double>();
    const json& b = shading["breakdown"];
    auto buys = [frame](double part, double s) {
        return frame > 0 && s > 0 ? frame / (frame - part + part / s) : 1.0;
    };
    json out = json::array();
    for (const json& k : weighed["top"])
        if (k["speedup"].is_number()) {
            const double s = k["speedup"].get<double>();
            out.push_back({{"key", k["key"]}, {"from", k["from"]}, {"to", k["to"]}, {"part", "traversal"},
                           {"part_speedup", s}, {"frame_speedup", buys(b["traversal"].get<double>(), s)}});
        }
    const double shade = b["shading"].get<double>();
    out.push_back({{"key", "shading.cores"}, {"from", config.shading.cores}, {"to", config.shading.cores * 2},
                   {"part", "shading"}, {"part_speedup", 2.0}, {"frame_speedup", buys(shade, 2.0)}});
    if (config.shading.reorder == ShadeReorder::none) {
        const double div = std::max(1.0, shading["divergence"].get<double>());
        out.push_back({{"key", "shading.reorder"}, {"from", "none"}, {"to", "shader"}, {"part", "shading"},
                       {"part_speedup", div}, {"frame_speedup", buys(shade, div)}});
    }
    std::stable_sort(out.begin(), out.end(), [](const json& x, const json& y) {
        return x["frame_speedup"].get<double>() > y["frame_speedup"].get<double>();
    });
    return out;
}

const StatBlock& verdict_stats() {
    static const StatBlock block{
        "verdict",
        {
            {"binding", "", "the resource named: `dram`, `l1_mshrs`, `l2_mshrs`, `l1_banks`, `l2_banks`, `l1_capacity`, `l2_capacity`, `units`, `<kind>` (a pipeline kind), `scheduler`, `stack`, `ray_buffer`, `admission`, `treelet_scheduling`, `latency`, `workload`, `divergence` (SIMT lanes idle)"},
            {"label", "", "the same in words (e.g. \"DRAM bandwidth\")"},
            {"text", "", "one sentence: label, evidence and the best relaxation with its estimated speed-up"},
            {"evidence", "", "`use` (the cycle-accounting use that points at it), `context_fraction` (that use's share of context cycles), `utilization.<resource>` (the utilisations that confirm it), `text` (the evidence in words)"},
            {"candidates", "list", "every knob, best first (by estimated gain; unestimated ones by `evidence`), each with `resource` (as `binding`), `key` (the `--set` knob that relaxes it), `from` and `to` (its values), `speedup` (the analytic estimate of cycles(from) / cycles(to); `null` without one, with `why_not`), `added_mm2` (the area model's added area), `gain_per_mm2` (`(speedup - 1) / added_mm2`; `null` for knobs the area model does not price: MSHRs, banks, channels, costs), `evidence` (the share of context cycles that points at the resource)"},
            {"top", "list", "the first three `candidates`: what to try, printed by `rtsim simulate`"},
            {"top_per_mm2", "list", "the three best `gain_per_mm2`"},
            {"co_limits", "list", "pairs of estimated knobs whose joint relaxation gains much more than either alone (joint gain >= 1.5 x the better single gain + 5 points): `keys`, `sets` (`key=value` each), `resources`, `joint` (estimated speed-up of both), `alone` (each's)"},
            {"coverage", "", "`estimated` (false where the analytic level does not model the machine: treelets), `why_not`, `frames` (an animated trace's estimates are the first frame's)"},
            {"check", "list", "with `--check-verdict`: each top candidate and co-limit re-run at the run's level: `sets`, `estimated`, `measured` (rays/s relaxed over the run's), `run` (its folder); best measured first", false, true},
            {"relax", "", "the best candidate, with the same fields; `null` when no knob relaxes the binding resource"},
            {"estimate", "", "`method` (the analytic level on N sampled rays, or on the stored per-trace analysis), `reused` (the analysis was loaded from beside the trace, stored there by an earlier run, instead of stepped by this one), `base_cycles` (its cycles for the run's own config), `wall_seconds` (the host time the estimates took)"},
            {"analytic_binding", "", "the analytic level's own binding bound for the same config (`model.analytic.binding`), a second opinion"},
            {"frame", "list", "only with `shading.enabled`: the shading side's knobs beside the RT unit's, weighed by what they buy the frame (Amdahl over `model.shading.breakdown`): `key`, `from`, `to`, `part` (traversal or shading), `part_speedup` (the RT knob's estimate; 2 for doubled shader cores; the divergence for sorting by shader, an upper bound), `frame_speedup`; best first", false, true},
        }};
    return block;
}

RTSIM_REGISTER_STAT_BLOCK(verdict_stats)

namespace {

ReportBlock verdict_report() {
    ReportBlock b;
    b.name = "verdict";
    b.order = 70;
    b.add = [](json& stats, const ReportInputs& in) {
        const json verdict = in.verdict ? in.verdict() : json(nullptr);
        stats["verdict"] = verdict;
        stats["summary"]["bottleneck"] = verdict.is_null() ? json(nullptr) : verdict["binding"];
        stats["summary"]["verdict"] = verdict.is_null() ? json(nullptr) : verdict["text"];
    };
    b.keys = {{"verdict", verdict_stats}};
    return b;
}

}  // namespace

RTSIM_REGISTER_REPORT_BLOCK(verdict_report())

}  // namespace rtsim
