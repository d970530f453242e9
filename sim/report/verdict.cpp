#include "sim/report/verdict.h"

#include <cctype>
#include "sim/report/report_block.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>

#include "sim/report/resources.h"
#include "sim/report/verdict_estimator.h"
#include "traces/common/error.h"

namespace rtsim {

using nlohmann::json;

namespace {

/// Utilisation at which a resource counts as saturated rather than merely slow.
constexpr double kSaturated = 0.7;
/// A run whose traversal waited for the build unit this share of its cycles is bound by it.
constexpr double kBuildBound = 0.5;
/// A structural alternative is named ahead of the best resource knob when its estimate beats
/// that knob's by this much: the analytic level's error between two designs' analyses is larger
/// than between two configs of one.
constexpr double kDesignMargin = 0.05;

std::string label_of(const std::string& resource) { return resource_label(resource); }

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

bool per_unit(const SimConfig& c, const std::string& resource) { return resource_per_unit(c, resource); }

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
        // What the structural alternatives would change (this orders the ones left to measure
        // and which of them --check-verdict re-runs): treelets cut DRAM waits when
        // off and cost ray-buffer and admission time when on; prefetching and sorting shorten
        // memory waits; another execution model removes masked-off lanes.
        const bool memory = use == "dram" || use == "l2" || use == "l2_mshr_full" || use == "l1_mshr_full";
        if (c.treelets.enabled ? (use == "ray_buffer" || use == "starved") : use == "dram") e.add("treelets", use, fraction);
        if (memory && !c.treelets.prefetch) e.add("prefetch", use, fraction / 2);
        if (memory && c.dispatch.sort == RaySort::none) e.add("ray_order", use, fraction / 4);
        if (use == "idle_lane") e.add("execution_model", use, fraction);
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

/// The evidence for `resource` in words, that resource's own: at the timed levels the cycle
/// use that points at it (and the share of all uses that do) with its own utilisation; at the
/// analytic level its bound against the largest. Where nothing points at it, the text says so
/// and names the largest use instead of passing that use off as its evidence.
json evidence_for(const std::string& resource, const Evidence& e, const json& model, bool timed) {
    const auto share_it = e.share.find(resource);
    const double share = share_it == e.share.end() ? 0.0 : share_it->second;
    if (!timed) {
        const json& bounds = model.value("analytic", json::object()).value("bounds", json::object());
        if (resource == e.largest) return {{"share", share}, {"text", "the analytic level's largest bound is " + resource}};
        if (bounds.contains(resource))
            return {{"share", share},
                    {"text", "the analytic level's " + resource + " bound is " + percent(share) + " of its largest (" +
                                 e.largest + ")"}};
        return {{"share", 0.0},
                {"text", "no bound of the analytic level is " + resource + "'s own (its largest is " + e.largest + ")"}};
    }
    const auto [top_use, top_fraction] = uses_by_size(model).front();
    const auto it = e.use.find(resource);
    if (it == e.use.end()) {
        json out = {{"use", nullptr}, {"context_fraction", 0.0}, {"share", 0.0}};
        std::string text = "no context cycle points at it";
        const std::string own = resource_busy(resource);
        if (!own.empty() && model.contains("utilization")) {
            out["utilization"] = {{own, utilization(model, own)}};
            text += " (" + own + " " + percent(utilization(model, own)) + " busy)";
        }
        out["text"] = text + "; the largest use: waiting for " + waiting_for(top_use) + " " + percent(top_fraction) +
                      " of their cycles";
        return out;
    }
    const std::string use = it->second;
    const double fraction = model["cycle_accounting"]["fractions"].value(use, 0.0);
    json out = {{"use", use}, {"context_fraction", fraction}, {"share", share}};
    std::string text = "contexts waited for " + waiting_for(use) + " " + percent(fraction) + " of their cycles";
    if (share > fraction + 0.005) text += " (" + percent(share) + " in all the uses that point at it)";
    // The resource's own utilisation confirms it (DRAM bandwidth for DRAM, whatever use
    // points there); a resource without one shows the use's (the L1 MSHRs for more units).
    std::string busy = resource_busy(resource);
    if (busy.empty()) resource_of_use(use, model, &busy);
    if (!busy.empty() && model.contains("utilization")) {
        out["utilization"] = {{busy, utilization(model, busy)}};
        text += ", " + busy + " " + percent(utilization(model, busy)) + " busy";
    }
    // The largest use too, so a knob named for a smaller use does not hide where time went.
    if (top_use != use) text += "; the largest use: waiting for " + waiting_for(top_use) + " " + percent(top_fraction);
    out["text"] = text;
    return out;
}

/// "not estimated (why)", without repeating "not estimated" when the reason already says it.
std::string not_estimated(std::string why) {
    for (const char* lead : {"not estimated: ", "not estimated (", "not estimated"})
        if (why.rfind(lead, 0) == 0) why = why.substr(std::string(lead).size());
    while (!why.empty() && (why.back() == ')' && why.find('(') == std::string::npos)) why.pop_back();
    return why.empty() ? "not estimated" : "not estimated (" + why + ")";
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
    } else if (relax.value("structural", false)) {
        text += "; another design pays more than any resource knob: " + knob_text(relax) + " estimated by " +
                relax.value("estimated_by", std::string()) +
                (relax.value("trace", false) ? " (a new trace; measure: " + relax["measure"].get<std::string>() + ")"
                                             : "");
    } else if (relax["speedup"].is_number()) {
        text += "; " + knob_text(relax) + " estimated by the analytic level";
    } else if (not_covered.empty()) {
        text += "; " + knob_text(relax) + ": " + not_estimated(relax.value("why_not", std::string()));
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
    std::string savers;
    for (const json& k : weighed["area_savers"]) {
        char mm2[48];
        std::snprintf(mm2, sizeof mm2, " %+.3f mm^2", k["added_mm2"].get<double>());
        savers += (savers.empty() ? "" : ", ") + k["key"].get<std::string>() + "=" + value_text(k["to"]) + " " +
                  gain(k["speedup"].get<double>()) + mm2;
    }
    if (!savers.empty()) text += "; same speed, less area: " + savers;
    if (!not_covered.empty()) text += "; " + not_covered;
    // Another design is not a step of a resource: name the alternatives, priced, with the
    // estimate of those the analytic level could cost on their own analysis.
    std::string estimated, measured;
    for (const json& k : weighed["structural"]) {
        if (k.contains("refused") || (!relax.is_null() && k["key"] == relax["key"] && k["to"] == relax["to"])) continue;
        char mm2[48] = "";
        if (k["added_mm2"].is_number()) std::snprintf(mm2, sizeof mm2, " %+.3f mm^2", k["added_mm2"].get<double>());
        const std::string item = k["key"].get<std::string>() + "=" + value_text(k["to"]) +
                                 (k["speedup"].is_number() ? " " + gain(k["speedup"].get<double>()) : "") + mm2;
        std::string& list = k["speedup"].is_number() ? estimated : measured;
        list += (list.empty() ? "" : ", ") + item;
    }
    if (!estimated.empty()) text += "; other designs, estimated: " + estimated;
    if (!measured.empty())
        text += "; other designs, not estimated, measure them (verdict.structural has each command): " + measured;
    // An estimate that names a resource no context cycle points at disagrees with the run's own
    // accounting: say so rather than let the two read as one story.
    if (!relax.is_null() && relax["speedup"].is_number() && v["evidence"].value("share", 1.0) < 0.02 &&
        v["evidence"].contains("use"))
        text += "; the cycle accounting does not point at " + v["binding"].get<std::string>() +
                ": estimate and accounting disagree, measure with --check-verdict";
    return text;
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
    const bool pipeline = resource_op_kind(resource, &kind);
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
                   not_covered, evidence.share, c.unit.knobs, c.structure,
                   [&](const SimConfig& x) { return estimator.dram_bytes(x); }};
    in.structural = [&](const Knob& k) { return estimator.structural(k, c.config); };
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
    // Another design the estimates put clearly ahead of every resource knob is the one to try
    // first (it needs a new trace or config: its `measure`); the binding stays the resource
    // that binds this design.
    const json& design = weighed["structural"].empty() ? json(nullptr) : weighed["structural"][0];
    const double resource_best = !best.is_null() && best["speedup"].is_number() ? best["speedup"].get<double>() : 1.0;
    if (!design.is_null() && design["speedup"].is_number() && design["speedup"].get<double>() >= 1.02 &&
        design["speedup"].get<double>() > resource_best + kDesignMargin)
        relax = design;
    json v = {{"binding", binding},
              {"label", label_of(binding)},
              {"evidence", evidence_for(binding, evidence, c.model, timed)},
              {"relax", relax},
              {"candidates", weighed["knobs"]},
              {"top", weighed["top"]},
              {"top_per_mm2", weighed["top_per_mm2"]},
              {"area_savers", weighed["area_savers"]},
              {"co_limits", weighed["co_limits"]},
              {"structural", weighed["structural"]},
              {"coverage", {{"estimated", not_covered.empty()},
                            {"why_not", not_covered.empty() ? json(nullptr) : json(not_covered)},
                            {"frames", c.frames}}},
              {"analytic_binding", analytic_binding},
              {"estimate",
               {{"method", estimator.method()},
                {"reused", estimator.reused()},
                {"base_cycles", base_cycles},
                {"dram_latency", estimator.dram_calibration().to_json()},
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
    if (c.model.contains("build_unit") && c.model["build_unit"].is_object()) {
        v["build"] = build_knobs(c.model["build_unit"], weighed, c.config);
        // A frame that mostly waits for its build is bound by the build unit, whatever binds
        // its traversal: the traversal's best knob buys only its part (Amdahl).
        const double share = c.model["build_unit"].value("share", 0.0);
        const json& top = v["build"].empty() ? json(nullptr) : v["build"][0];
        if (share >= kBuildBound && !top.is_null() && top["part"] == "build") {
            v["binding"] = "build";
            v["label"] = label_of("build");
            v["relax"] = {{"key", top["key"]}, {"from", top["from"]}, {"to", top["to"]}, {"resource", "build"},
                          {"speedup", nullptr}, {"run_speedup", top["run_speedup"]},
                          {"why_not", "the analytic level does not model the build unit; at most " +
                                          gain(top["run_speedup"].get<double>()) +
                                          " to the run, by Amdahl over its share: measure it"}};
            v["evidence"] = {{"use", "build"}, {"context_fraction", share}, {"share", share},
                             {"text", "the traversal waited for the build unit " + percent(share) + " of the run's cycles"}};
        }
    }
    v["text"] = verdict_text(v, weighed, not_covered);
    if (c.model.contains("shading")) v["frame"] = frame_knobs(c.model["shading"], weighed, c.config);
    return v;
}

namespace {

/// What a part of `share` of the whole, sped up by s, buys the whole (Amdahl).
double amdahl(double share, double s) { return s > 0 ? 1.0 / (1.0 - share + share / s) : 1.0; }

/// A knob of one side of a run split in two parts: `part` speeds by `part_speedup`, which buys
/// the whole `whole_key` (Amdahl over `share`, the part's share of the whole).
json side_knob(json key, json from, json to, const char* part, double part_speedup, double share,
               const char* whole_key) {
    return {{"key", std::move(key)}, {"from", std::move(from)}, {"to", std::move(to)}, {"part", part},
            {"part_speedup", part_speedup}, {whole_key, amdahl(share, part_speedup)}};
}

/// The RT unit's estimated top knobs as the traversal side (`share` of the whole), then `more`,
/// best first by what each buys the whole.
json two_sides(const json& weighed, double share, const char* whole_key, std::vector<json> more) {
    json out = json::array();
    for (const json& k : weighed["top"])
        if (k["speedup"].is_number())
            out.push_back(side_knob(k["key"], k["from"], k["to"], "traversal", k["speedup"].get<double>(), share, whole_key));
    for (json& k : more) out.push_back(std::move(k));
    std::stable_sort(out.begin(), out.end(), [whole_key](const json& x, const json& y) {
        return x[whole_key].get<double>() > y[whole_key].get<double>();
    });
    return out;
}

}  // namespace

json build_knobs(const json& build_unit, const json& weighed, const SimConfig& config) {
    // A moving scene's run is its frames' builds (the traversal waits at each barrier) and their
    // traversal: each side's knob buys the run its part, by Amdahl, like frame_knobs. The build
    // side is an upper bound: doubling a throughput halves the build's compute, and its memory
    // stream only if the outstanding lines keep up.
    const double share = build_unit.value("share", 0.0);
    // A build job takes the longer of its compute and its memory stream: halving one buys the
    // build at most busy / max(half of it, the other).
    const double busy = build_unit.value("busy_cycles", 0.0), compute = build_unit.value("compute_cycles", 0.0),
                 stream = build_unit.value("stream_cycles", 0.0);
    auto halved = [busy](double part, double other) {
        const double after = std::max(part / 2, other);
        return after > 0 ? std::max(1.0, busy / after) : 1.0;
    };
    const double compute_s = halved(compute, stream), stream_s = halved(stream, compute);
    const BuildUnitConfig& b = config.build_unit;
    std::vector<json> build;
    if (build_unit.value("rebuilds", 0) > 0)
        build.push_back(side_knob("build_unit.rebuild_triangles_per_cycle", b.rebuild_triangles_per_cycle,
                                  b.rebuild_triangles_per_cycle * 2, "build", compute_s, share, "run_speedup"));
    if (build_unit.value("refits", 0) > 0)
        build.push_back(side_knob("build_unit.refit_nodes_per_cycle", b.refit_nodes_per_cycle, b.refit_nodes_per_cycle * 2,
                                  "build", compute_s, share, "run_speedup"));
    // More lines in flight halves the stream at best (when its latency, not DRAM, paces it).
    build.push_back(side_knob("build_unit.outstanding_lines", b.outstanding_lines, b.outstanding_lines * 2, "build",
                              stream_s, share, "run_speedup"));
    if (!b.overlap && share > 0) {
        // Building beside the previous frame's rays hides the build behind the traversal (or the
        // traversal behind the build): the run becomes the longer of the two, an upper bound
        // (their shared memory slows both). The build's part is then what stays exposed.
        const double exposed = std::max(0.0, share - (1.0 - share));
        build.push_back({{"key", "build_unit.overlap"}, {"from", false}, {"to", true}, {"part", "build"},
                         {"part_speedup", exposed > 0 ? json(share / exposed) : json(nullptr)},
                         {"run_speedup", 1.0 / std::max(share, 1.0 - share)}});
    }
    return two_sides(weighed, 1.0 - share, "run_speedup", std::move(build));
}

json frame_knobs(const json& shading, const json& weighed, const SimConfig& config) {
    // What each side's knob buys the frame, by Amdahl over the frame's breakdown (docs/shading.md):
    // a part sped up by s leaves frame / (frame - part + part / s). The RT unit's best estimated
    // knob speeds traversal; doubling the shader cores or sorting by shader speeds shading (the
    // latter by the warps' divergence, the programs a sorted warp no longer serialises).
    const double frame = shading["frame_cycles"].get<double>();
    const json& b = shading["breakdown"];
    auto share_of = [frame](double part) { return frame > 0 ? part / frame : 0.0; };
    const double shade = share_of(b["shading"].get<double>());
    std::vector<json> shading_side = {
        side_knob("shading.cores", config.shading.cores, config.shading.cores * 2, "shading", 2.0, shade, "frame_speedup")};
    if (config.shading.reorder == ShadeReorder::none) {
        const double div = std::max(1.0, shading["divergence"].get<double>());
        shading_side.push_back(side_knob("shading.reorder", "none", "shader", "shading", div, shade, "frame_speedup"));
    }
    return two_sides(weighed, share_of(b["traversal"].get<double>()), "frame_speedup", std::move(shading_side));
}

const StatBlock& verdict_stats() {
    static const StatBlock block{
        "verdict",
        {
            {"binding", "", "the resource named: `dram`, `l1_mshrs`, `l2_mshrs`, `l1_banks`, `l2_banks`, `l1_capacity`, `l2_capacity`, `units`, `<kind>` (a pipeline kind), `scheduler`, `stack`, `ray_buffer`, `admission`, `treelet_scheduling`, `latency`, `workload`, `divergence` (SIMT lanes idle), `build` (the build unit: a moving scene's frames waiting for their builds)"},
            {"label", "", "the same in words (e.g. \"DRAM bandwidth\")"},
            {"text", "", "one sentence: label, evidence and the best relaxation with its estimated speed-up"},
            {"evidence", "", "the named resource's own evidence: `use` (the cycle-accounting use that points at it; `null` when none does), `context_fraction` (that use's share of context cycles), `share` (the share of context cycles of every use that points at it; at the analytic level its bound over the largest), `utilization.<resource>` (the resource's own utilisation, else the use's), `text` (the evidence in words: says so when no use points at the resource)"},
            {"candidates", "list", "every knob, best first (by estimated gain; unestimated ones by `evidence`), each with `resource` (as `binding`), `key` (the `--set` knob that relaxes it), `from` and `to` (its values), `speedup` (the analytic estimate of cycles(from) / cycles(to); `null` without one, with `why_not`), `added_mm2` (the area model's added area), `gain_per_mm2` (`(speedup - 1) / added_mm2`; `null` for knobs the area model does not price: MSHRs, banks, channels, costs), `evidence` (the share of context cycles that points at the resource), `dram_saved_fraction` (estimated: the share of DRAM traffic the knob removes) and `dram_nj_saved_per_ray` (that share of the run's DRAM energy per ray: what it saves per ray in joules), `tie_break` (present when it was named ahead of an estimate within 3 points because it also removes DRAM traffic)"},
            {"top", "list", "the first three `candidates`: what to try, printed by `rtsim simulate`"},
            {"top_per_mm2", "list", "the three best `gain_per_mm2`"},
            {"area_savers", "list", "up to three candidates that keep the run's speed (an estimate of at least 0.98x) and save area (`added_mm2` below 0), most saved first: a kind's private pipelines shared by the units (`KIND.sharing=shared`) where few of its tests run"},
            {"co_limits", "list", "pairs of estimated knobs whose joint relaxation gains much more than either alone (joint gain >= 1.5 x the better single gain + 5 points): `keys`, `sets` (`key=value` each), `resources`, `joint` (estimated speed-up of both), `alone` (each's)"},
            {"coverage", "", "`estimated` (false where the analytic level does not model the machine: treelets), `why_not`, `frames` (an animated trace's estimates are the first frame's)"},
            {"structural", "list", "the structural alternatives to the run's design, one step each: another structure (`accel`: a wide BVH, or compressed nodes) and `compressed_leaves` (both a new trace), `treelets.enabled` flipped, another `traversal.model`, `dispatch.sort` on or off, `treelets.prefetch` flipped, and for an animated trace the other `frame_policy` values (a new trace: `rtsim trace --frame-policy`); each with the candidates' fields (`speedup` and `estimated_by` for another structure or compressed leaves estimated on the alternative trace beside the run's, `rtsim trace --alternatives`, and for treelets flipped or the other execution model estimated on the run's trace; else `speedup` null and `why_not`), `structural` (true), `trace` (needs a new trace), `measure` (the command that measures it; `--check-verdict` re-runs the best estimated one and the best that needs no new trace) and `added_mm2` (its added area: the decoders of compressed nodes or leaves, a ray buffer, SIMT control, a sort stage, a prefetcher); `refused` when the config refuses it"},
            {"check", "list", "with `--check-verdict`: each top candidate, the best co-limit and the structural alternatives re-run (the best estimated one, on its own trace for another structure; the best needing no new trace) at the run's level: `sets`, `estimated`, `measured` (rays/s relaxed over the run's), `run` (its folder), `trace` (a re-run on the alternative trace); best measured first", false, true},
            {"relax", "", "the best candidate, with the same fields, or the best estimated `structural` alternative when it pays five points more than any candidate; `null` when no knob relaxes the binding resource"},
            {"estimate", "", "`method` (the analytic level on N sampled rays, or on the stored per-trace analysis), `reused` (the analysis was loaded from beside the trace, stored there by an earlier run, instead of stepped by this one), `base_cycles` (its cycles for the run's own config), `dram_latency` (timed runs with the bank model: `added_cycles`, what each DRAM access is charged beyond `dram.latency`, the run's own row outcome `row_cycles` rounded; `bank_wait_cycles`, its bank wait, reported but not charged; `null` otherwise), `wall_seconds` (the host time the estimates took)"},
            {"analytic_binding", "", "the analytic level's own binding bound for the same config (`model.analytic.binding`), a second opinion"},
            {"frame", "list", "only with `shading.enabled`: the shading side's knobs beside the RT unit's, weighed by what they buy the frame (Amdahl over `model.shading.breakdown`): `key`, `from`, `to`, `part` (traversal or shading), `part_speedup` (the RT knob's estimate; 2 for doubled shader cores; the divergence for sorting by shader, an upper bound), `frame_speedup`; best first", false, true},
            {"build", "list", "only for a moving scene whose frames build (`model.build_unit`): the build unit's knobs beside the RT unit's, weighed by what they buy the run (Amdahl over `model.build_unit.share`): `key`, `from`, `to`, `part` (traversal or build), `part_speedup` (the RT knob's estimate; for a doubled build throughput `busy / max(compute / 2, stream)`, for doubled outstanding lines `busy / max(stream / 2, compute)`, over `model.build_unit`'s cycles: upper bounds, and with `build_unit.overlap` lower ones, since a build beside the traversal leaves exposed only what outlasts it; `build_unit.overlap` on: what stays exposed of the build, `null` when all of it hides behind the traversal), `run_speedup` (for `build_unit.overlap`, `1 / max(share, 1 - share)`: the run as the longer of its builds and its traversal, an upper bound); best first. When the build holds the run at least half its cycles and a build knob leads, `binding` is `build`", false, true},
            {"agreement", "", "the run's answers in one vocabulary: `binding`, `knob` (the named knob's key), `relaxes` (the resources it relaxes, directly or by what it removes), `roofline_bound` (`roofline.bound`), `roofline_reached` (achieved over that ceiling), `roofline_relaxed`, `analytic_binding`, `analytic_relaxed` (whether the knob relaxes each)"},
        }};
    return block;
}

RTSIM_REGISTER_STAT_BLOCK(verdict_stats)

namespace {

bool list_contains(const std::vector<std::string>& list, const std::string& x) {
    return std::find(list.begin(), list.end(), x) != list.end();
}

/// The run's three answers side by side in one vocabulary (resources.h): the verdict's binding
/// and named knob, the roofline's lowest ceiling, the analytic level's binding bound, and
/// whether the named knob relaxes each. The roofline runs first (report order 60).
json agreement_json(const json& v, const json& roofline, const SimConfig& c) {
    const json& relax = v["relax"];
    const std::string key = relax.is_null() ? std::string() : relax["key"].get<std::string>();
    std::vector<std::string> relaxed = key.empty() ? std::vector<std::string>{} : knob_relaxes(c, key);
    if (!relax.is_null() && !list_contains(relaxed, relax["resource"].get<std::string>()))
        relaxed.push_back(relax["resource"].get<std::string>());
    const std::string bound = roofline.is_object() ? roofline.value("bound", std::string()) : std::string();
    const std::string analytic = v["analytic_binding"].get<std::string>();
    json out = {{"binding", v["binding"]}, {"knob", key.empty() ? json(nullptr) : json(key)},
                {"relaxes", relaxed},      {"roofline_bound", bound.empty() ? json(nullptr) : json(bound)},
                {"analytic_binding", analytic}};
    out["roofline_relaxed"] = bound.empty() ? json(nullptr) : json(list_contains(relaxed, bound));
    out["analytic_relaxed"] = list_contains(relaxed, analytic);
    double reached = 0;
    if (!bound.empty() && roofline["bound_rays_per_second"].is_number() && roofline["rays_per_second"].is_number() &&
        roofline["bound_rays_per_second"].get<double>() > 0)
        reached = roofline["rays_per_second"].get<double>() / roofline["bound_rays_per_second"].get<double>();
    out["roofline_reached"] = reached;
    return out;
}

/// The agreement in words: the ceiling and the binding bound by name, and what the knob does
/// to each.
std::string agreement_text(const json& a) {
    std::string text = " (";
    const bool roof = a["roofline_bound"].is_string();
    if (roof)
        text += "roofline: lowest ceiling " + a["roofline_bound"].get<std::string>() + ", " +
                percent(a["roofline_reached"].get<double>()) + " of it reached; ";
    text += "analytic binding: " + a["analytic_binding"].get<std::string>();
    if (a["knob"].is_string()) {
        const std::string k = a["knob"].get<std::string>();
        const bool r = roof && a["roofline_relaxed"].get<bool>(), an = a["analytic_relaxed"].get<bool>();
        const bool same = roof && a["roofline_bound"] == a["analytic_binding"];
        if ((r || !roof) && an) text += "; " + k + " relaxes " + (roof && !same ? "both" : "it");
        else if (r) text += "; " + k + " relaxes the ceiling, not the analytic binding";
        else if (an) text += "; " + k + " relaxes the analytic binding, not the ceiling";
        else text += "; " + k + " relaxes " + (roof && !same ? "neither" : "not it") + ": it pays only by what it removes elsewhere";
    }
    return text + ")";
}

std::string gain_text(double speedup) { return gain(speedup); }

/// "; re-run: K=V measured +x% (estimated +y%), ..." for a verdict with `check`.
std::string checked_clause(const json& verdict) {
    std::string text = "; re-run:";
    bool first = true;
    for (const json& c : verdict["check"]) {
        std::string sets;
        for (const json& s : c["sets"]) sets += (sets.empty() ? "" : " + ") + s.get<std::string>();
        const std::string measured = c["measured"].is_number() ? gain_text(c["measured"].get<double>()) : "(failed)";
        const std::string estimated = c["estimated"].is_number() ? gain_text(c["estimated"].get<double>()) : "-";
        text += std::string(first ? " " : ", ") + sets + " measured " + measured + " (estimated " + estimated + ")";
        first = false;
    }
    return text;
}

ReportBlock verdict_report() {
    ReportBlock b;
    b.name = "verdict";
    b.order = 70;
    b.add = [](json& stats, const ReportInputs& in) {
        json verdict = in.verdict ? in.verdict() : json(nullptr);
        if (!verdict.is_null()) {
            // Each knob's DRAM energy saved per ray: its share of DRAM traffic removed times the
            // run's own DRAM energy per ray (the energy block runs first, report order 50).
            const json& nj = stats.value("energy", json::object()).value("per_ray_nj", json::object());
            auto saved = [&](json& k) {
                if (k.is_object() && k.contains("dram_saved_fraction"))
                    k["dram_nj_saved_per_ray"] = k["dram_saved_fraction"].get<double>() * nj["dram"].get<double>();
            };
            if (nj.contains("dram") && nj["dram"].is_number()) {
                for (const char* list : {"candidates", "top", "top_per_mm2", "area_savers"})
                    for (json& k : verdict[list]) saved(k);
                saved(verdict["relax"]);
            }
            verdict["agreement"] = agreement_json(verdict, stats.value("roofline", json(nullptr)), in.config);
            verdict["text"] = verdict["text"].get<std::string>() + agreement_text(verdict["agreement"]);
            if (verdict.contains("check")) verdict["text"] = verdict["text"].get<std::string>() + checked_clause(verdict);
            // A run too small to answer its question says so in the same sentence (study_size.cpp).
            const json& size = stats.value("study_size", json(nullptr));
            if (size.is_object() && size.value("too_small", false))
                for (const json& f : size["findings"])
                    verdict["text"] = verdict["text"].get<std::string>() + "; too small: " + f["text"].get<std::string>();
        }
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
