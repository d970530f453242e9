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

struct Resource {
    const char* label;  ///< what a person calls it
};

const std::map<std::string, Resource>& resources() {
    static const std::map<std::string, Resource> r = {
        {"l1_mshrs", {"L1 MSHRs"}},
        {"l2_mshrs", {"L2 MSHRs"}},
        {"dram", {"DRAM bandwidth"}},
        {"l1_banks", {"L1 banks"}},
        {"l2_banks", {"L2 banks"}},
        {"latency", {"latency not hidden (memory and pipeline latency over too few ray contexts)"}},
        {"scheduler", {"the traversal units' schedulers (one step per issue_cycles)"}},
        {"stack", {"stack spills (spilled entries read back)"}},
        {"ray_buffer", {"the ray buffer SRAM"}},
        {"workload", {"the workload: too few rays to keep the machine busy (contexts idle)"}},
    };
    return r;
}

std::string label_of(const std::string& resource) {
    auto it = resources().find(resource);
    if (it != resources().end()) return it->second.label;
    return resource + " pipelines";  // an operation kind
}

/// What a context waits for, in words, for each cycle use.
std::string waiting_for(const std::string& use) {
    static const std::map<std::string, std::string> w = {
        {"l1_mshr_full", "a free L1 MSHR"},  {"l2_mshr_full", "a free L2 MSHR"},
        {"dram", "data from DRAM"},          {"l2", "data from the L2"},
        {"l1_hit", "data from its L1"},      {"issue", "its unit's scheduler"},
        {"stack", "spilled stack entries"},  {"ray_buffer", "the ray buffer"},
        {"dispatch", "dispatch"},            {"starved", "a ray (starved)"},
        {"tail", "nothing: the workload had run out"}};
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

Relaxation relaxation_for(const std::string& resource, const SimConfig& c) {
    auto doubled = [](const char* key, uint32_t value, uint32_t max) {
        return value * 2 <= max ? Relaxation{key, value, value * 2} : Relaxation{};
    };
    if (resource == "l1_mshrs") return doubled("l1.mshrs", c.l1.mshrs, 1024);
    if (resource == "l2_mshrs") return doubled("l2.mshrs", c.l2.mshrs, 1024);
    if (resource == "dram") return doubled("dram.channels", c.dram.channels, 64);
    if (resource == "l1_banks") return doubled("l1.banks", c.l1.banks, 256);
    if (resource == "l2_banks") return doubled("l2.banks", c.l2.banks, 256);
    if (resource == "latency") return doubled("traversal.ray_contexts", c.traversal.ray_contexts, 4096);
    if (resource == "stack") return doubled("traversal.stack_entries", c.traversal.stack_entries, 64);
    if (resource == "ray_buffer") return doubled("treelets.bytes_per_cycle", c.treelets.bytes_per_cycle, 4096);
    if (resource == "scheduler") {
        if (c.traversal.issue_cycles > 1)
            return {"traversal.issue_cycles", c.traversal.issue_cycles, c.traversal.issue_cycles / 2};
        return doubled("traversal.units", c.traversal.units, 4096);
    }
    for (int k = 0; k < kOpKindCount; ++k) {
        if (resource != op_kind_name(OpKind(k))) continue;
        const PipelineConfig& p = c.pipeline(OpKind(k));
        const std::string base = resource + ".";
        if (p.shared()) return doubled((base + "shared_count").c_str(), p.shared_count, 1024);
        if (p.initiation_interval > 1) return {base + "initiation_interval", p.initiation_interval, p.initiation_interval / 2};
        return doubled((base + "width").c_str(), p.width, 64);
    }
    return {};  // the workload: no hardware knob
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
    static const std::map<std::string, std::string> busy_of = {
        {"l1_mshrs", "l1_mshrs"}, {"l2_mshrs", "l2_mshrs"}, {"dram", "dram_bandwidth"},
        {"l1_banks", "l1_banks"}, {"l2_banks", "l2_banks"}};
    auto busy = busy_of.find(binding);
    if (busy != busy_of.end() && !evidence.value("utilization", json::object()).contains(busy->second) &&
        c.model.contains("utilization")) {
        const double u = utilization(c.model, busy->second);
        v["evidence"]["utilization"][busy->second] = u;
        text += "; " + busy->second + " " + percent(u) + " busy";
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

}  // namespace rtsim
