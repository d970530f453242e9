#include "sim/analytic/closed_form.h"

#include <algorithm>
#include <cmath>

#include "rtl_model/isect/pipeline.h"
#include "traces/common/error.h"
#include "rtl_model/top/model_stats.h"

namespace rtsim {

using nlohmann::json;

namespace {

/// The L2's MSHRs and the DRAM channels as a closed loop (simultaneous resource possession: a
/// miss holds its MSHR while it queues for a channel). At most `l2.mshrs` misses are outstanding;
/// each spends the DRAM latency as a pure delay and its share of a channel's bus (all DRAM bytes,
/// writes too, spread evenly over the channels) in a queue. Mean value analysis of that loop with
/// every MSHR busy gives the most misses per cycle the L2 can have served; the bound is the
/// misses over that rate. Unloaded and without writes it equals l2_hold / mshrs (writes, which
/// hold no MSHR, are charged to the misses' channel time: slightly pessimistic when they are
/// many and the MSHRs few); near the DRAM's peak it adds the queueing that keeps the MSHRs held
/// longer (what -18% on a DRAM-saturated machine missed).
/// Row-buffer hits and conflicts are not known here: every miss costs the closed-bank latency.
double l2_loop_bound(const SimConfig& c, const AnalyticDemands& d) {
    const double service = std::ceil(double(c.l2.line_bytes) / c.dram.bytes_per_cycle);
    const double misses = d.l2_hold / (double(c.dram.latency) + service);  // l2_hold: misses x that
    if (misses <= 0) return 0;
    const double channels = c.dram.channels;
    const double demand = d.dram_bytes / c.dram.bytes_per_cycle / misses / channels;  // per channel
    double queue = 0, x = 0;
    for (uint32_t n = 1; n <= c.l2.mshrs; ++n) {
        const double r = demand * (1.0 + queue);  // residence at one channel (all alike)
        x = double(n) / (double(c.dram.latency) + channels * r);
        queue = x * r;
    }
    return misses / x;
}

json bounds_of(const SimConfig& c, const std::vector<OpKind>& ops, const AnalyticDemands& d) {
    const TraversalConfig& t = c.traversal;
    json b = json::object();
    for (OpKind kind : ops) {
        const PipelineConfig& pc = c.pipeline(kind);
        const double pipelines = pc.shared() ? pc.shared_count : t.units;
        b[op_kind_name(kind)] = d.issues[size_t(kind)] * pc.initiation_interval / pipelines;
    }
    if (!c.ideal_memory) {
        b["dram"] = d.dram_bytes / (double(c.dram.channels) * c.dram.bytes_per_cycle);
        b["l2_banks"] = d.l2_accesses * c.l2.bank_cycles / c.l2.banks;
        b["l1_banks"] = d.l1_accesses * c.l1.bank_cycles / (double(c.l1.banks) * t.units);
        b["l1_mshrs"] = d.l1_hold / (double(c.l1.mshrs) * t.units);
        b["l2_mshrs"] = std::max(d.l2_hold / double(c.l2.mshrs), l2_loop_bound(c, d));
    }
    b["scheduler"] = d.scheduler_steps * t.issue_cycles / t.units;
    if (c.treelets.enabled) b["ray_buffer"] = d.ray_buffer_bytes / c.treelets.bytes_per_cycle;
    b["latency"] = std::max(d.latency_sum / (double(t.units) * t.contexts()), d.latency_max);
    return b;
}

/// Mean value analysis (Reiser & Lavenberg 1980) of the ray contexts as a closed queueing
/// network: each unit's `ray_contexts` rays circulate through the resources behind the bounds
/// (each a queue whose demand per ray is its bound's share) and a pure delay (the rest of the
/// unloaded latency). Units are symmetric classes: a private resource queues one unit's rays, a
/// shared one (DRAM, L2, shared pipelines) all units' rays. An m-server resource (MSHRs) is a
/// queue of demand D/m plus a delay (Seidmann et al. 1987). The throughput it gives is never
/// above any bound, and it adds the queueing the roofline leaves out when several resources are
/// loaded at once. Returns the cycles for all rays; `below_l1_wait`, when given, the cycles all
/// rays waited in the queues an L1 miss waits in holding its MSHR (the L2's MSHRs, the DRAM).
/// `population` > 0: that many customers per unit (fractional: the throughputs of the integers
/// either side interpolated), each with the rays' unloaded latency as its delay (a window of a
/// run's phases, whose active contexts are fewer than the unit's at the fill and the drain).
double mva_cycles(const SimConfig& c, const std::vector<OpKind>& ops, const AnalyticDemands& d, const json& bounds,
                  double* below_l1_wait = nullptr, double population = 0) {
    const double rays = d.visits > 0 ? d.visits : d.rays, units = c.traversal.units;
    if (rays <= 0) return 0;
    const uint32_t customers = population > 0 ? uint32_t(std::ceil(population))
                               : d.customers > 0 ? uint32_t(std::lround(d.customers))
                                                 : c.traversal.contexts();
    struct Station {
        double demand;  ///< cycles per ray of one class (unit)
        bool shared;
        bool below_l1;  ///< an L1 miss waits there holding its L1 MSHR (the L2's MSHRs, the DRAM)
    };
    std::vector<std::pair<std::string, bool>> kinds;  // station, shared by all units
    for (OpKind kind : ops) kinds.push_back({op_kind_name(kind), c.pipeline(kind).shared()});
    for (const char* name : {"scheduler", "l1_banks", "l1_mshrs"}) kinds.push_back({name, false});
    for (const char* name : {"dram", "l2_banks", "l2_mshrs", "ray_buffer"}) kinds.push_back({name, true});
    std::vector<Station> stations;
    // Unloaded latency per visit: the rays' residence over the visits, shared by each customer's
    // rays (a group's rays wait together).
    // (A customer of a lock-step kind is a group: its visit's delay is one group step's, its
    // rays' residence over the rays per group; contexts: one ray's.)
    const double per_customer = d.group_rays > 0   ? 1.0 / d.group_rays
                                : d.customers > 0 ? d.customers / double(c.traversal.contexts())
                                                  : 1.0;
    double think = d.latency_sum / rays * per_customer;
    for (const auto& [name, shared] : kinds) {
        if (!bounds.contains(name)) continue;
        const double bound = bounds[name].get<double>();
        const double demand = shared ? bound / rays : bound * units / rays;
        stations.push_back({demand, shared, name == "l2_mshrs" || name == "dram"});
        // The delay is the unloaded latency less the service the stations add back: the MSHR
        // queues' unloaded demand D/m, and the pipelines', banks' and DRAM bus's service (a
        // pipeline's initiation intervals, a bank's cycle and a line's transfer are in the
        // unloaded latency). The scheduler's issue cycles are not, so its demand stays on top.
        // The L2's bound holds DRAM queueing too (l2_loop_bound): only its unloaded part is in
        // the latency.
        if (name == "l2_mshrs") think -= d.l2_hold / double(c.l2.mshrs) / rays;
        else if (name != "scheduler") think -= demand;
    }
    think = std::max(think, 0.0);
    std::vector<double> queue(stations.size(), 0.0), r(stations.size());
    double x = 0, x_below = 0;
    for (uint32_t n = 1; n <= customers; ++n) {
        x_below = x;
        double residence = think;
        for (size_t k = 0; k < stations.size(); ++k) {
            r[k] = stations[k].demand * (1.0 + (stations[k].shared ? units : 1.0) * queue[k]);
            residence += r[k];
        }
        x = double(n) / residence;  // rays per cycle of one unit
        for (size_t k = 0; k < stations.size(); ++k) queue[k] = x * r[k];
    }
    if (below_l1_wait) {
        *below_l1_wait = 0;
        for (size_t k = 0; k < stations.size(); ++k)
            if (stations[k].below_l1) *below_l1_wait += (r[k] - stations[k].demand) * rays;
    }
    if (population > 0 && population < customers) x = x_below + (x - x_below) * (population - (customers - 1));
    return x > 0 ? rays / (units * x) : 0.0;
}

/// A share of the demands (a window of the run's phases).
AnalyticDemands scaled(const AnalyticDemands& d, const PhaseShare& s) {
    AnalyticDemands w = d;
    w.rays = d.rays * s.work;
    w.visits = d.visits * s.steps;  // a lock-step kind's group steps (0 for contexts)
    for (double& i : w.issues) i *= s.work;
    w.scheduler_steps *= s.steps;
    w.l1_accesses *= s.reads;
    w.l2_accesses *= s.l1_misses;
    w.l1_hold *= s.l1_misses;
    w.dram_bytes *= s.l2_misses;
    w.l2_hold *= s.l2_misses;
    w.ray_buffer_bytes *= s.steps;
    w.latency_sum = s.latency_sum;
    w.latency_max = 0;  // the windows' rounds hold the longest ray
    return w;
}

/// The demands with each L1 miss holding its MSHR also while it waits below: for an L2 MSHR and
/// for a DRAM channel (simultaneous resource possession, as in l2_loop_bound one level down). The
/// unloaded hold leaves those waits out, so designs short of MSHRs at both levels were estimated
/// up to 18% fast against detailed (docs/fidelity.md, "Where designs starve or fill slowly"); the waits come from the mean value analysis itself, a fixed
/// point (damped, eight rounds: the hold changes the waits little once the L1's bound binds).
AnalyticDemands with_waits_below_l1(const SimConfig& c, const std::vector<OpKind>& ops, const AnalyticDemands& d) {
    AnalyticDemands held = d;
    if (c.ideal_memory) return held;
    for (int round = 0; round < 8; ++round) {
        double wait = 0;
        mva_cycles(c, ops, held, bounds_of(c, ops, held), &wait);
        held.l1_hold = 0.5 * held.l1_hold + 0.5 * (d.l1_hold + wait);
    }
    return held;
}

}  // namespace

ClosedForm closed_form(const SimConfig& c, const std::vector<OpKind>& ops, const AnalyticDemands& d,
                       const std::vector<PhaseShare>& phases) {
    ClosedForm f;
    const AnalyticDemands held = with_waits_below_l1(c, ops, d);
    f.bounds = bounds_of(c, ops, held);
    // A bound that is not a number would drop out of the roofline unseen (and write null).
    for (auto& [name, value] : f.bounds.items())
        require(value.is_number() && std::isfinite(value.get<double>()),
                "analytic: the closed form's '" + name + "' bound is not a finite number (a bug in its demands)");
    // Bounds within a billionth of each other tie, and the first named binds: the L2's MSHRs held
    // only by DRAM waits tie with the DRAM, their cause, which "dram" names first.
    f.binding = "latency";
    for (auto& [name, value] : f.bounds.items()) {
        const double v = value.get<double>();
        if (v > f.roofline * (1.0 + 1e-9)) f.binding = name;
        f.roofline = std::max(f.roofline, v);
    }
    f.queueing = mva_cycles(c, ops, held, f.bounds);
    f.cycles = std::max(f.roofline, f.queueing);
    f.steady_cycles = std::ceil(f.cycles);
    double phased = 0;
    for (const PhaseShare& s : phases) {
        const AnalyticDemands w = scaled(held, s);
        const json wb = bounds_of(c, ops, w);
        double window = mva_cycles(c, ops, w, wb, nullptr, std::max(s.population, 1e-3));
        for (auto& [name, value] : wb.items()) {
            require(value.is_number() && std::isfinite(value.get<double>()),
                    "analytic: a phase window's '" + name + "' bound is not a finite number (a bug in its shares)");
            if (name != "latency") window = std::max(window, value.get<double>());
        }
        require(std::isfinite(window), "analytic: a phase window's mean value analysis is not a finite number");
        phased += window;
    }
    if (f.cycles > 0 && phased > f.cycles) f.phase_factor = phased / f.cycles, f.cycles = phased;
    f.cycles = std::ceil(f.cycles);
    f.dram_bytes = c.ideal_memory ? 0.0 : d.dram_bytes;
    return f;
}

const StatBlock& analytic_stats() {
    static const StatBlock block{
        "model.analytic",
        {
            {"bounds", "cycles", "`{resource: cycles}`: each resource's roofline bound (the closed form's terms below)"},
            {"binding", "", "the name of the largest bound"},
            {"roofline_cycles", "cycles", "the largest bound"},
            {"queueing_cycles", "cycles", "the mean-value-analysis estimate (never below the roofline's throughput bounds)"},
            {"cycles", "cycles", "`max(roofline_cycles, queueing_cycles)` times `phase_factor`, rounded up: `summary.cycles`"},
            {"phase_factor", "", "whole-trace analyses on the analysed machine: the run's phases (fill, steady state, drain), each window priced as a run of its own (the larger of its mean value analysis at its population and its bounds), their sum over max(roofline_cycles, queueing_cycles) when it is larger (1: no phases, or a sum below)"},
            {"unloaded_latency_mean_cycles", "cycles", "mean unloaded ray latency"},
            {"unloaded_latency_max_cycles", "cycles", "longest unloaded ray latency"},
            {"merge_wait_cycles", "cycles", "mean wait per planned step for a line whose earlier miss is still in flight (merged misses, which the reuse distances count as hits); in the unloaded latency"},
            {"convoy_contexts", "contexts", "contexts that run alone: how many one fill releases at once (its first read's and the merged reads' that wait for it), which then step on together: the mean value analysis's customers are the contexts over it (1: no merges)"},
            {"caches", "", "`statistical` (reuse distances of a sample, the default) or `functional` (every ray through functional caches)"},
            {"assignment", "", "functional caches only: how rays are assigned to contexts and how contexts interleave (text)", false, true},
            {"analysis", "", "statistical only: `file` (the per-trace analysis beside the trace), `reused` (loaded, or built by this run), `seconds`, `stepped_rays`, `sample_rays` (what building it cost) and `key` (what it depends on)", false, true},
        }};
    return block;
}

void check_analytic_model(const json& model, const std::string& unit_kind) {
    check_model_stats(model, unit_kind);
    if (model.contains("analytic")) analytic_stats().check(model.at("analytic"));
}

json closed_form_json(const ClosedForm& f, const AnalyticDemands& d) {
    return {{"bounds", f.bounds},
            {"binding", f.binding},
            {"roofline_cycles", f.roofline},
            {"queueing_cycles", f.queueing},
            {"cycles", f.cycles},
            {"phase_factor", f.phase_factor},
            {"unloaded_latency_mean_cycles", d.rays > 0 ? d.latency_sum / d.rays : 0.0},
            {"unloaded_latency_max_cycles", d.latency_max},
            {"merge_wait_cycles", d.merge_wait},
            {"convoy_contexts", d.convoy}};
}

json pipelines_json(const SimConfig& c, const std::vector<OpKind>& ops, const std::vector<std::vector<double>>& unit_issues,
                    const std::vector<std::vector<double>>& unit_tests, double cycles) {
    json m = json::object();
    for (OpKind kind : ops) {
        const size_t p = size_t(kind);
        const std::string name = op_kind_name(kind);
        const PipelineConfig& pc = c.pipeline(kind);
        auto block = [&](double issues, double tests, uint32_t pipelines) {
            const double capacity = cycles * pipelines / pc.initiation_interval;
            json j;
            StatsWriter(pipeline_stats(), j)
                .set("issues", issues)
                .set("tests", tests)
                .set("pipelines", pipelines)
                .set("utilization", capacity > 0 ? issues / capacity : 0.0)
                .untimed()
                .done();
            return j;
        };
        if (pc.shared()) {
            double issues = 0, tests = 0;
            for (size_t u = 0; u < unit_issues.size(); ++u) issues += unit_issues[u][p], tests += unit_tests[u][p];
            m[name][name + "_pool"] = block(issues, tests, pc.shared_count);
        } else {
            for (size_t u = 0; u < unit_issues.size(); ++u)
                m[name][name + "_" + std::to_string(u)] = block(unit_issues[u][p], unit_tests[u][p], 1);
        }
    }
    return m;
}

json analytic_instantiated(const SimConfig& c, const std::string& accel_kind, const std::vector<OpKind>& ops,
                           const std::string& memory_why) {
    json out = json::array(
        {{{"block", "traversal"}, {"instantiated", true},
          {"why", traversal_units_text(c.traversal) + " (analytic: counted, not timed)"}},
         {{"block", "memory"}, {"instantiated", !c.ideal_memory},
          {"why", c.ideal_memory ? std::string(kIdealMemoryWhy) : memory_why}}});
    for (int k = 0; k < kOpKindCount; ++k) {
        const bool used = std::find(ops.begin(), ops.end(), OpKind(k)) != ops.end();
        out.push_back({{"block", op_kind_name(OpKind(k))},
                       {"instantiated", used},
                       {"why", std::string("the ") + accel_kind + " structure issues " + (used ? "" : "no ") +
                                   op_kind_name(OpKind(k)) + " operations (analytic: counted, not timed)"}});
    }
    return out;
}

RTSIM_REGISTER_STAT_BLOCK(analytic_stats)

}  // namespace rtsim
