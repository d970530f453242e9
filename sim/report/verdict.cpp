#include "sim/report/verdict.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>

#include "sim/analytic/analytic.h"
#include "sim/harness/trace_stream.h"
#include "traces/common/error.h"

namespace rtsim {

using nlohmann::json;

namespace {

/// Utilisation at which a resource counts as saturated rather than merely slow.
constexpr double kSaturated = 0.7;

/// The resources the verdict can name besides the pipelines: the name the analytic bounds and
/// stats use, what a person calls it, the utilisation that shows it busy (model.utilization;
/// "" if none) and the config knob that relaxes it, doubled ("" if none, or a rule below).
struct ResourceInfo {
    const char* name;
    const char* label;
    const char* busy;
    const char* knob;
};

const std::vector<ResourceInfo>& resource_table() {
    static const std::vector<ResourceInfo> r = {
        {"l1_mshrs", "L1 MSHRs", "l1_mshrs", "l1.mshrs"},
        {"l2_mshrs", "L2 MSHRs", "l2_mshrs", "l2.mshrs"},
        {"dram", "DRAM bandwidth", "dram_bandwidth", "dram.channels"},
        {"l1_banks", "L1 banks", "l1_banks", "l1.banks"},
        {"l2_banks", "L2 banks", "l2_banks", "l2.banks"},
        {"latency", "latency not hidden (memory and pipeline latency over too few ray contexts)", "",
         "traversal.ray_contexts"},
        {"scheduler", "the traversal units' schedulers (one step per issue_cycles)", "", ""},
        {"stack", "stack spills (spilled entries read back)", "", "traversal.stack_entries"},
        {"ray_buffer", "the ray buffer SRAM", "", "treelets.bytes_per_cycle"},
        {"workload", "the workload: too few rays to keep the machine busy (contexts idle)", "", ""},
        {"divergence", "SIMT divergence (warp lanes masked off while others step)", "", ""},
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

/// Evenly spread blocks of the trace's rays: a cheap sample for the analytic estimates.
class SampleStream : public RayStream {
public:
    SampleStream(TraceReader& reader, uint64_t sample) : m_reader(reader) {
        const uint64_t total = reader.section(SectionKind::rays).record_count;
        const uint64_t blocks = total <= sample ? 1 : 16, block = total <= sample ? total : sample / blocks;
        for (uint64_t b = 0; b < blocks; ++b) m_blocks.push_back({b * (total / blocks), block});
        m_total = blocks * block;
    }
    size_t read_chunk(size_t max, std::vector<RayJob>* out) override {
        if (m_next == m_blocks.size()) return 0;
        auto& [first, left] = m_blocks[m_next];
        const size_t n = size_t(std::min<uint64_t>(max, left));
        read_ray_jobs(m_reader, first, n, &m_buffer, out);
        first += n;
        left -= n;
        if (left == 0) ++m_next;
        return n;
    }
    uint64_t total_rays() const override { return m_total; }

private:
    TraceReader& m_reader;
    std::vector<std::pair<uint64_t, uint64_t>> m_blocks;  ///< first ray, rays left
    size_t m_next = 0;
    uint64_t m_total = 0;
    std::vector<RayRecord> m_buffer;
};

class DiscardSink : public RaySinkIf {
public:
    void ray_done(const RayResult&) override {}
};

/// The analytic level on the sample: its cycles and its binding bound.
std::pair<double, std::string> analytic_on_sample(const VerdictContext& c, const SimConfig& config) {
    if (c.estimate) return c.estimate(config);
    SampleStream stream(*c.reader, c.sample_rays);
    DiscardSink sink;
    const AnalyticOutcome a = run_analytic(config, *c.accel, *c.map, stream, sink);
    return {double(a.cycles), a.model["analytic"].value("binding", "")};
}

/// The config the analytic level can run: no treelets (its closed form models plain dispatch)
/// and no sampling (it runs on its own sample).
SimConfig analytic_config(SimConfig config) {
    config.fidelity = Fidelity::analytic;
    config.treelets.enabled = false;
    config.sampling = SamplingConfig{};
    // The closed form times each ray context on its own: a SIMT machine's relaxations are
    // estimated for the MIMD machine with the same contexts (divergence is not in it).
    config.traversal.model = UnitModel::mimd;
    return config;
}

/// The speed-up the analytic level estimates on the sample for one relaxation (null if the
/// relaxed config is invalid, with why_not).
json estimate(const VerdictContext& c, const SimConfig& base, double base_cycles, const Relaxation& relax) {
    json out = {{"key", relax.key}, {"from", relax.from}, {"to", relax.to}};
    SimConfig relaxed = base;
    try {
        config_set(relaxed, relax.key + "=" + relax.to.dump());
        validate(relaxed);
        const double cycles = analytic_on_sample(c, relaxed).first;
        out["speedup"] = cycles > 0 ? base_cycles / cycles : 1.0;
    } catch (const Error& e) {
        out["speedup"] = nullptr;
        out["why_not"] = e.what();
    }
    return out;
}

/// Cycle uses of a timed run, largest first.
std::vector<std::pair<std::string, double>> uses_by_size(const json& model) {
    std::vector<std::pair<std::string, double>> uses;
    const json& fractions = model.at("cycle_accounting").at("fractions");
    for (auto it = fractions.begin(); it != fractions.end(); ++it) uses.push_back({it.key(), it.value().get<double>()});
    std::stable_sort(uses.begin(), uses.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
    return uses;
}

/// Resources that may bind a timed run: those behind its largest cycle uses, and downstream of a
/// full MSHR file the saturated resources its misses wait on (an L1 whose MSHRs are full because
/// its misses queue at the L2's MSHRs is bound by the L2's, not its own).
std::vector<std::string> timed_candidates(const json& model, json* evidence) {
    const auto uses = uses_by_size(model);
    std::vector<std::string> out;
    auto add = [&](const std::string& r) {
        if (std::find(out.begin(), out.end(), r) == out.end()) out.push_back(r);
    };
    double covered = 0;
    for (size_t i = 0; i < uses.size() && i < 3 && covered < 0.8; ++i) {
        const auto& [use, fraction] = uses[i];
        std::string busy;
        add(resource_of_use(use, model, &busy));
        if (use == "l1_mshr_full" && utilization(model, "l2_mshrs") >= kSaturated) add("l2_mshrs");
        if ((use == "l1_mshr_full" || use == "l2_mshr_full") && utilization(model, "dram_bandwidth") >= kSaturated)
            add("dram");
        if (i == 0) {
            std::string text = "contexts waited for " + waiting_for(use) + " " + percent(fraction) + " of their cycles";
            *evidence = {{"use", use}, {"context_fraction", fraction}};
            if (!busy.empty()) {
                (*evidence)["utilization"] = {{busy, utilization(model, busy)}};
                text += " (" + busy + " " + percent(utilization(model, busy)) + " busy)";
            }
            (*evidence)["text"] = text;
        }
        covered += fraction;
    }
    return out;
}

}  // namespace

/// The knob `key` doubled, within the range its config field declares; none past the range.
Relaxation doubled(const SimConfig& c, const std::string& key) {
    const ConfigField f = config_field(c, key);
    const double value = f.value.get<double>();
    if (value * 2 > f.max) return {};
    return {key, f.value, json(f.value.get<uint64_t>() * 2)};
}

/// The knob `key` halved (a cost per operation, at least its declared minimum).
Relaxation halved(const SimConfig& c, const std::string& key) {
    const ConfigField f = config_field(c, key);
    const uint64_t value = f.value.get<uint64_t>();
    if (value / 2 < f.min || value < 2) return {};
    return {key, f.value, json(value / 2)};
}

Relaxation relaxation_for(const std::string& resource, const SimConfig& c) {
    OpKind kind;
    if (op_kind_of(resource, &kind)) {
        const PipelineConfig& p = c.pipeline(kind);
        const std::string base = resource + ".";
        if (p.shared()) return doubled(c, base + "shared_count");
        if (p.initiation_interval > 1) return halved(c, base + "initiation_interval");
        return doubled(c, base + "width");
    }
    if (resource == "divergence") return halved(c, "traversal.lanes");  // narrower warps diverge less
    if (resource == "scheduler")
        return c.traversal.issue_cycles > 1 ? halved(c, "traversal.issue_cycles") : doubled(c, "traversal.units");
    const ResourceInfo* r = find_resource(resource);
    return r && *r->knob ? doubled(c, r->knob) : Relaxation{};  // the workload: no hardware knob
}

json judge(const VerdictContext& c) {
    if (c.config.fidelity == Fidelity::functional) return nullptr;
    const auto start = std::chrono::steady_clock::now();
    const SimConfig base = analytic_config(c.config);
    const auto [base_cycles, analytic_binding] = analytic_on_sample(c, base);
    json evidence;
    std::vector<std::string> candidates;
    if (c.config.fidelity == Fidelity::analytic) {
        evidence = {{"text", "the analytic level's binding bound is " + analytic_binding}};
    } else {
        candidates = timed_candidates(c.model, &evidence);
    }
    if (std::find(candidates.begin(), candidates.end(), analytic_binding) == candidates.end())
        candidates.push_back(analytic_binding);
    // Each candidate's relaxation, estimated; the binding resource is the one whose relaxation
    // buys the most (when none buys 2%, the largest cycle use stands).
    json tried = json::array();
    std::string binding = candidates.front();
    double best = 1.02;
    for (const std::string& r : candidates) {
        const Relaxation relax = relaxation_for(r, c.config);
        json t = relax.key.empty() ? json{{"key", nullptr}, {"speedup", nullptr}} : estimate(c, base, base_cycles, relax);
        t["resource"] = r;
        if (t["speedup"].is_number() && t["speedup"].get<double>() > best) {
            best = t["speedup"].get<double>();
            binding = r;
        }
        tried.push_back(t);
    }
    json chosen = nullptr;
    for (const json& t : tried)
        if (t["resource"] == binding) chosen = t;
    json v = {{"binding", binding},
              {"label", label_of(binding)},
              {"evidence", evidence},
              {"relax", chosen["key"].is_null() ? json(nullptr) : chosen},
              {"candidates", tried},
              {"analytic_binding", analytic_binding},
              {"estimate",
               {{"method", c.estimate ? c.estimate_method
                                      : "analytic level on " +
                                            std::to_string(SampleStream(*c.reader, c.sample_rays).total_rays()) +
                                            " sampled rays" + (c.config.treelets.enabled ? " (treelets off)" : "")},
                {"base_cycles", base_cycles},
                {"wall_seconds",
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()}}}};
    std::string text = v["label"].get<std::string>() + ": " + evidence.value("text", std::string());
    const std::string busy = busy_of(binding);
    if (!busy.empty() && busy.rfind("pipe_", 0) != 0 &&
        !evidence.value("utilization", json::object()).contains(busy) && c.model.contains("utilization")) {
        const double u = utilization(c.model, busy);
        v["evidence"]["utilization"][busy] = u;
        text += "; " + busy + " " + percent(u) + " busy";
    }
    if (chosen["key"].is_null()) {
        text += "; no hardware knob relaxes it";
    } else {
        text += "; " + chosen["key"].get<std::string>() + " " + chosen["from"].dump() + " -> " + chosen["to"].dump() + ": ";
        if (chosen["speedup"].is_number()) {
            char buf[64];
            std::snprintf(buf, sizeof buf, "%+.0f%%", 100.0 * (chosen["speedup"].get<double>() - 1.0));
            text += std::string(buf) + " estimated by the analytic level";
        } else {
            text += "no estimate (" + chosen.value("why_not", std::string("?")) + ")";
        }
    }
    text += " (analytic binding bound: " + analytic_binding + ")";
    v["text"] = text;
    return v;
}

const StatBlock& verdict_stats() {
    static const StatBlock block{
        "verdict",
        {
            {"binding", "", "the resource named: `dram`, `l1_mshrs`, `l2_mshrs`, `l2`, `l1_banks`, `pipe_<kind>`, `scheduler`, `stack`, `ray_buffer`, `dispatch`, `latency`, `divergence` (SIMT lanes idle)"},
            {"label", "", "the same in words (e.g. \"DRAM bandwidth\")"},
            {"text", "", "one sentence: label, evidence and the best relaxation with its estimated speed-up"},
            {"evidence", "", "`use` (the cycle-accounting use that points at it), `context_fraction` (that use's share of context cycles), `utilization.<resource>` (the utilisations that confirm it), `text` (the evidence in words)"},
            {"candidates", "list", "best first, each with `resource` (as `binding`), `key` (the `--set` knob that relaxes it), `from` and `to` (its values), `speedup` (the analytic estimate of cycles(from) / cycles(to)) and, without an estimate, `why_not`"},
            {"relax", "", "the best candidate, with the same fields; `null` when no knob relaxes the binding resource"},
            {"estimate", "", "`method` (the analytic level on N sampled rays), `base_cycles` (its cycles for the run's own config on that sample), `wall_seconds` (the host time the estimates took)"},
            {"analytic_binding", "", "the analytic level's own binding bound for the same config (`model.analytic.binding`), a second opinion"},
        }};
    return block;
}

}  // namespace rtsim
