#include "sim/harness/analytic.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <memory>
#include <queue>
#include <string>
#include <vector>

#include "rtl_model/dispatch/dispatch.h"
#include "rtl_model/mem/functional_cache.h"
#include "rtl_model/traversal/stack_spill.h"

namespace rtsim {

using nlohmann::json;

namespace {

/// Per-unit counts (the analytic counterpart of a traversal unit and its pipelines).
struct UnitCounts {
    uint64_t rays = 0, steps = 0, spill_writes = 0, spill_reads = 0, rejected = 0;
    uint64_t issues[kOpKindCount] = {}, tests[kOpKindCount] = {};  ///< per operation kind
};

class AnalyticModel {
public:
    AnalyticModel(const SimConfig& config, const Accel& accel, const MemoryMap& map, RaySinkIf& sink)
        : m_c(config), m_map(map), m_sink(sink), m_ops(accel.op_kinds()), m_units(config.traversal.units),
          m_contexts(size_t(config.traversal.units) * config.traversal.ray_contexts) {
        for (Context& ctx : m_contexts) ctx.stepper = accel.make_stepper();
        if (!config.ideal_memory) {
            for (uint32_t u = 0; u < config.traversal.units; ++u) m_l1.emplace_back(config.l1);
            m_l2 = std::make_unique<FunctionalCache>(config.l2);
        }
        m_line_bytes = config.l1.line_bytes;
    }

    void run(RayStream& rays);
    AnalyticOutcome outcome(const Accel& accel) const;

private:
    struct Context {
        std::unique_ptr<Stepper> stepper;
        uint64_t id = 0;
        Cycle clock = 0;    ///< this context's unloaded clock
        Cycle start = 0;    ///< clock the ray started at
        uint32_t local_stack = 0, spilled = 0;
        bool active = false;
    };
    bool start_ray(uint32_t unit, uint32_t slot);
    void step(uint32_t unit, uint32_t slot);
    Cycle read(uint32_t unit, uint64_t addr, uint32_t bytes, DataKind kind, Cycle now);
    void write(uint32_t unit, uint64_t addr, uint32_t bytes, DataKind kind);
    Cycle stack_traffic(uint32_t unit, uint32_t slot, int before, Cycle now);
    Cycle pipe(uint32_t unit, const Op& op);
    bool uses(OpKind kind) const { return std::find(m_ops.begin(), m_ops.end(), kind) != m_ops.end(); }
    json bounds_json(double* cycles, std::string* binding) const;
    double queueing_cycles(const json& bounds) const;

    const SimConfig& m_c;
    const MemoryMap& m_map;
    RaySinkIf& m_sink;
    std::vector<OpKind> m_ops;  ///< operation kinds the structure issues
    std::vector<UnitCounts> m_units;
    std::vector<Context> m_contexts;  ///< unit-major: unit * ray_contexts + context
    std::vector<FunctionalCache> m_l1;
    std::unique_ptr<FunctionalCache> m_l2;
    MemStats m_dram, m_ideal;
    uint32_t m_line_bytes = 64;
    std::unique_ptr<Dispatch> m_dispatch;  ///< the model's dispatch block: same ray-to-unit policy
    uint64_t m_dispatched = 0;
    double m_latency_sum = 0;
    Cycle m_latency_max = 0;
    double m_l1_hold = 0, m_l2_hold = 0;  ///< cycles L1 / L2 misses hold an MSHR, summed
};

void AnalyticModel::run(RayStream& rays) {
    m_dispatch = std::make_unique<Dispatch>("analytic_dispatch", m_c.dispatch, m_c.traversal.units, rays);
    const uint32_t units = m_c.traversal.units, contexts = m_c.traversal.ray_contexts;
    // The context whose unloaded clock is earliest takes the next step (ties: context-major,
    // then unit, so the first rays spread over the units); a context that finishes a ray takes
    // the next one at once. The clocks order the accesses and detect fills in flight only.
    using Entry = std::pair<Cycle, uint32_t>;  // clock, c * units + u
    std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> ready;
    for (uint32_t c = 0; c < contexts; ++c)
        for (uint32_t u = 0; u < units; ++u)
            if (start_ray(u, c)) ready.push({m_contexts[size_t(u) * contexts + c].clock, c * units + u});
    while (!ready.empty()) {
        const uint32_t key = ready.top().second;
        ready.pop();
        const uint32_t u = key % units, c = key / units;
        step(u, c);
        const Context& ctx = m_contexts[size_t(u) * contexts + c];
        if (ctx.active) ready.push({ctx.clock, key});
    }
}

bool AnalyticModel::start_ray(uint32_t unit, uint32_t slot) {
    RayJob job;
    if (!m_dispatch->next_ray(unit, &job)) return false;
    ++m_dispatched;
    Context& ctx = m_contexts[size_t(unit) * m_c.traversal.ray_contexts + slot];
    ctx.stepper->begin(job.ray, job.any_hit ? TraversalMode::any_hit : TraversalMode::closest_hit);
    if (!ray_is_valid(job.ray)) ++m_units[unit].rejected;
    ctx.id = job.id;
    ctx.local_stack = ctx.spilled = 0;
    ctx.active = true;
    ++m_units[unit].steps;  // the ray-fetch step
    ctx.start = ctx.clock;
    const Cycle fetch = ctx.clock + m_c.dispatch.latency;
    ctx.clock = fetch + read(unit, m_map.ray(job.id), sizeof(RayRecord), DataKind::ray, fetch);
    return true;
}

void AnalyticModel::step(uint32_t unit, uint32_t slot) {
    Context& ctx = m_contexts[size_t(unit) * m_c.traversal.ray_contexts + slot];
    UnitCounts& uc = m_units[unit];
    Stepper& stepper = *ctx.stepper;
    const StepPlan& plan = stepper.plan();
    if (plan.done) {
        write(unit, m_map.hit(ctx.id), sizeof(HitRecord), DataKind::hit);  // posted
        const Cycle latency = ctx.clock - ctx.start;
        m_sink.ray_done(RayResult{ctx.id, stepper.hit(), stepper.work(), 0, latency, unit, slot});
        ++uc.rays;
        m_latency_sum += double(latency);
        m_latency_max = std::max(m_latency_max, latency);
        ctx.active = false;
        start_ray(unit, slot);
        return;
    }
    // The step as the traversal unit takes it: its fetches, then its operations in order, then
    // those its results call for (alpha tests); two scheduler steps (fetch, operations).
    uc.steps += 2;
    Cycle fetched = 0;
    for (int i = 0; i < plan.fetch_count; ++i)
        fetched = std::max(fetched, read(unit, plan.fetch[i].addr, plan.fetch[i].bytes, plan.fetch[i].kind, ctx.clock));
    ctx.clock += fetched;
    Op ops[StepPlan::kMaxOps];
    const int op_count = plan.op_count;
    std::copy(plan.op, plan.op + op_count, ops);
    const int before = stepper.stack_size();
    const StepOutcome outcome = stepper.execute();
    Cycle ready = 0;
    for (int i = 0; i < op_count; ++i) ready += pipe(unit, ops[i]);
    for (int i = 0; i < outcome.op_count; ++i) ready += pipe(unit, outcome.op[i]);
    ctx.clock += std::max(ready, stack_traffic(unit, slot, before, ctx.clock));
}

/// Issues an operation into its pipeline; returns its unloaded latency.
Cycle AnalyticModel::pipe(uint32_t unit, const Op& op) {
    const PipelineConfig& pc = m_c.pipeline(op.kind);
    const uint32_t issues = (op.count + pc.width - 1) / pc.width;
    m_units[unit].issues[size_t(op.kind)] += issues;
    m_units[unit].tests[size_t(op.kind)] += op.count;
    return issues ? Cycle(issues - 1) * pc.initiation_interval + pc.latency : 0;
}

/// One read through L1, L2 and DRAM at cycle `now` (line by line, as Cache does); returns the
/// unloaded latency of its slowest line, including the wait for a fill in flight (a merge).
Cycle AnalyticModel::read(uint32_t unit, uint64_t addr, uint32_t bytes, DataKind kind, Cycle now) {
    if (m_c.ideal_memory) {
        MemCounters& c = m_ideal[kind];
        ++c.reads;
        ++c.read_hits;
        c.read_bytes += bytes;
        return m_c.l1.latency;
    }
    const uint32_t shift = m_l1[unit].line_shift();
    const Cycle ic = m_c.interconnect_latency;
    const Cycle dram = m_c.dram.latency + (m_line_bytes + m_c.dram.bytes_per_cycle - 1) / m_c.dram.bytes_per_cycle;
    Cycle done = now;
    for (uint64_t line = addr >> shift; line <= (addr + std::max<uint32_t>(bytes, 1) - 1) >> shift; ++line) {
        const uint64_t lo = std::max(addr, line << shift), hi = std::min(addr + bytes, (line + 1) << shift);
        const uint32_t part = uint32_t(hi > lo ? hi - lo : 0);
        const Cycle l1_tag = now + m_c.l1.latency;
        Cycle ready = 0, *fill = nullptr;
        if (m_l1[unit].read(line, part, kind, l1_tag, &ready, &fill)) {
            done = std::max(done, std::max(l1_tag, ready));
            continue;
        }
        // L1 miss: to the L2 over the interconnect; its fill comes back the same way.
        const Cycle l2_tag = l1_tag + ic + m_c.l2.latency;
        Cycle l2_ready = 0, *l2_fill = nullptr, l2_done;
        if (m_l2->read(line, m_line_bytes, kind, l2_tag, &l2_ready, &l2_fill)) {
            l2_done = std::max(l2_tag, l2_ready);
        } else {
            l2_done = *l2_fill = l2_tag + dram;
            m_l2_hold += double(dram);
            MemCounters& d = m_dram[kind];
            ++d.reads;
            ++d.read_hits;
            d.read_bytes += m_line_bytes;
        }
        *fill = l2_done + ic;
        m_l1_hold += double(*fill - l1_tag);
        done = std::max(done, *fill);
    }
    return done - now;
}

/// A posted write: write-through, no-write-allocate at every level, one request per line piece.
void AnalyticModel::write(uint32_t unit, uint64_t addr, uint32_t bytes, DataKind kind) {
    if (m_c.ideal_memory) {
        ++m_ideal[kind].writes;
        m_ideal[kind].write_bytes += bytes;
        return;
    }
    const uint32_t shift = m_l1[unit].line_shift();
    for (uint64_t line = addr >> shift; line <= (addr + std::max<uint32_t>(bytes, 1) - 1) >> shift; ++line) {
        const uint64_t lo = std::max(addr, line << shift), hi = std::min(addr + bytes, (line + 1) << shift);
        const uint32_t part = uint32_t(hi > lo ? hi - lo : 0);
        m_l1[unit].write(part, kind);
        m_l2->write(part, kind);
        ++m_dram[kind].writes;
        m_dram[kind].write_bytes += part;
    }
}

/// Stack spills (posted writes) and refills (reads the ray waits for), as the traversal unit
/// maps the stepper's stack onto stack_entries on-chip entries; returns the refill latency.
Cycle AnalyticModel::stack_traffic(uint32_t unit, uint32_t slot, int before, Cycle now) {
    Context& ctx = m_contexts[size_t(unit) * m_c.traversal.ray_contexts + slot];
    const uint32_t bytes = m_c.traversal.stack_entry_bytes;
    const uint64_t owner = uint64_t(unit) * m_c.traversal.ray_contexts + slot;
    Cycle refill = 0;
    map_stack_change(
        ctx.local_stack, ctx.spilled, before, ctx.stepper->stack_size(), m_c.traversal.stack_entries,
        [&](uint32_t s) {
            write(unit, m_map.stack(owner, s, bytes), bytes, DataKind::stack);
            ++m_units[unit].spill_writes;
        },
        [&](uint32_t s) {
            ++m_units[unit].spill_reads;
            refill = std::max(refill, read(unit, m_map.stack(owner, s, bytes), bytes, DataKind::stack, now));
        });
    return refill;
}

/// The roofline: each bound in cycles; `cycles` gets the largest, `binding` its name.
json AnalyticModel::bounds_json(double* cycles, std::string* binding) const {
    const TraversalConfig& t = m_c.traversal;
    uint64_t issues[kOpKindCount] = {}, steps = 0;
    for (const UnitCounts& u : m_units) {
        for (int k = 0; k < kOpKindCount; ++k) issues[k] += u.issues[k];
        steps += u.steps;
    }
    json b = json::object();
    for (OpKind kind : m_ops) {
        const PipelineConfig& pc = m_c.pipeline(kind);
        const double pipelines = pc.shared() ? pc.shared_count : t.units;
        b[op_kind_name(kind)] = double(issues[size_t(kind)]) * pc.initiation_interval / pipelines;
    }
    if (!m_c.ideal_memory) {
        MemCounters d = m_dram.total(), l2 = m_l2->stats().total();
        uint64_t l1_accesses = 0;
        for (const FunctionalCache& l1 : m_l1) l1_accesses += l1.stats().total().reads + l1.stats().total().writes;
        b["dram"] = double(d.read_bytes + d.write_bytes) / (double(m_c.dram.channels) * m_c.dram.bytes_per_cycle);
        b["l2_banks"] = double(l2.reads + l2.writes) * m_c.l2.bank_cycles / m_c.l2.banks;
        b["l1_banks"] = double(l1_accesses) * m_c.l1.bank_cycles / (double(m_c.l1.banks) * t.units);
        // Little's law on the MSHRs: each miss holds one for its unloaded miss latency.
        b["l1_mshrs"] = m_l1_hold / (double(m_c.l1.mshrs) * t.units);
        b["l2_mshrs"] = m_l2_hold / double(m_c.l2.mshrs);
    }
    b["scheduler"] = double(steps) * t.issue_cycles / t.units;
    b["latency"] = std::max(m_latency_sum / (double(t.units) * t.ray_contexts), double(m_latency_max));
    *cycles = 0;
    for (auto& [name, value] : b.items())
        if (value.get<double>() > *cycles) {
            *cycles = value.get<double>();
            *binding = name;
        }
    return b;
}

/// Mean value analysis (Reiser & Lavenberg 1980) of the ray contexts as a closed queueing
/// network: each unit's `ray_contexts` rays circulate through the resources behind the bounds
/// (each a queue whose demand per ray is its bound's share) and a pure delay (the rest of the
/// unloaded latency). Units are symmetric classes: a private resource queues one unit's rays, a
/// shared one (DRAM, L2, shared pipelines) all units' rays. An m-server resource (MSHRs) is a
/// queue of demand D/m plus a delay (Seidmann et al. 1987). The throughput it gives is never
/// above any bound, and it adds the queueing the roofline leaves out when several resources are
/// loaded at once. Returns the cycles for all rays.
double AnalyticModel::queueing_cycles(const json& bounds) const {
    const double rays = double(m_dispatched), units = m_c.traversal.units;
    if (rays == 0) return 0;
    struct Station {
        double demand;  ///< cycles per ray of one class (unit)
        bool shared;
    };
    std::vector<std::pair<std::string, bool>> kinds;  // station, shared by all units
    for (OpKind kind : m_ops) kinds.push_back({op_kind_name(kind), m_c.pipeline(kind).shared()});
    for (const char* name : {"scheduler", "l1_banks", "l1_mshrs"}) kinds.push_back({name, false});
    for (const char* name : {"dram", "l2_banks", "l2_mshrs"}) kinds.push_back({name, true});
    std::vector<Station> stations;
    double think = m_latency_sum / rays;  // unloaded latency per ray
    for (const auto& [name, shared] : kinds) {
        if (!bounds.contains(name)) continue;
        const double bound = bounds[name].get<double>();
        const double demand = shared ? bound / rays : bound * units / rays;
        stations.push_back({demand, shared});
        // The MSHR queues' demand D/m is part of the unloaded latency already.
        if (name.find("mshrs") != std::string::npos) think -= demand;
    }
    think = std::max(think, 0.0);
    std::vector<double> queue(stations.size(), 0.0);
    double x = 0;
    for (uint32_t n = 1; n <= m_c.traversal.ray_contexts; ++n) {
        double residence = think;
        std::vector<double> r(stations.size());
        for (size_t k = 0; k < stations.size(); ++k) {
            r[k] = stations[k].demand * (1.0 + (stations[k].shared ? units : 1.0) * queue[k]);
            residence += r[k];
        }
        x = double(n) / residence;  // rays per cycle of one unit
        for (size_t k = 0; k < stations.size(); ++k) queue[k] = x * r[k];
    }
    return x > 0 ? rays / (units * x) : 0.0;
}

AnalyticOutcome AnalyticModel::outcome(const Accel& accel) const {
    AnalyticOutcome out;
    double bound = 0;
    std::string binding = "latency";
    json bounds = bounds_json(&bound, &binding);
    const double queueing = queueing_cycles(bounds);
    out.cycles = Cycle(std::ceil(std::max(bound, queueing)));
    const double total = double(out.cycles);
    json& m = out.model;
    m["dispatch"] = m_dispatch->stats_json();
    for (size_t u = 0; u < m_units.size(); ++u) {
        const UnitCounts& uc = m_units[u];
        // Time-dependent counters do not exist at this level: null.
        m["units"]["tu" + std::to_string(u)] = {
            {"rays", uc.rays},          {"steps", uc.steps},      {"busy_cycles", nullptr},
            {"busy_fraction", nullptr}, {"stack_spill_writes", uc.spill_writes},
            {"stack_spill_reads", uc.spill_reads}, {"rejected_rays", uc.rejected},
            {"quantum_syncs", nullptr}, {"finish_cycle", nullptr}};
    }
    for (OpKind kind : m_ops) {
        const size_t p = size_t(kind);
        const std::string name = op_kind_name(kind);
        const PipelineConfig& pc = m_c.pipeline(kind);
        auto block = [&](uint64_t issues, uint64_t tests, uint32_t pipelines) {
            const double capacity = total * pipelines / pc.initiation_interval;
            return json{{"issues", issues},     {"tests", tests}, {"pipelines", pipelines},
                        {"utilization", capacity > 0 ? double(issues) / capacity : 0.0}, {"avg_wait_cycles", nullptr}};
        };
        if (pc.shared()) {
            uint64_t issues = 0, tests = 0;
            for (const UnitCounts& uc : m_units) issues += uc.issues[p], tests += uc.tests[p];
            m[name][name + "_pool"] = block(issues, tests, pc.shared_count);
        } else {
            for (size_t u = 0; u < m_units.size(); ++u)
                m[name][name + "_" + std::to_string(u)] = block(m_units[u].issues[p], m_units[u].tests[p], 1);
        }
    }
    if (m_c.ideal_memory) {
        m["ideal_memory"] = m_ideal.to_json();
    } else {
        for (size_t u = 0; u < m_l1.size(); ++u) m["l1"]["l1_" + std::to_string(u)] = m_l1[u].stats_json();
        m["l2"] = m_l2->stats_json();
        json d = m_dram.to_json();
        auto drop_cache_fields = [](json& c) {
            for (const char* k : {"read_hits", "merged", "hit_rate"}) c.erase(k);
        };
        drop_cache_fields(d);
        for (auto& [kind, c] : d["by_kind"].items()) drop_cache_fields(c);
        const MemCounters t = m_dram.total();
        const double seconds = total / (m_c.clock_ghz * 1e9);
        const double peak = double(m_c.dram.bytes_per_cycle) * m_c.dram.channels * m_c.clock_ghz;
        const double achieved = seconds > 0 ? double(t.read_bytes + t.write_bytes) / seconds / 1e9 : 0.0;
        d["bandwidth_gbps"] = achieved;
        d["peak_bandwidth_gbps"] = peak;
        d["bandwidth_utilization"] = peak > 0 ? achieved / peak : 0.0;
        d["avg_queue_cycles"] = nullptr;
        d["bandwidth_over_time"] = json::array();
        m["dram"] = d;
    }
    const double rays = double(m_dispatched);
    m["analytic"] = {{"bounds", bounds},
                     {"binding", binding},
                     {"roofline_cycles", bound},
                     {"queueing_cycles", queueing},
                     {"cycles", out.cycles},
                     {"unloaded_latency_mean_cycles", rays > 0 ? m_latency_sum / rays : 0.0},
                     {"unloaded_latency_max_cycles", m_latency_max},
                     {"assignment", "rays to contexts in trace order as contexts free up; contexts of all units "
                                    "step in round robin"}};
    const TraversalConfig& tc = m_c.traversal;
    out.instantiated = json::array(
        {{{"block", "traversal"}, {"instantiated", true},
          {"why", std::to_string(tc.units) + " units x " + std::to_string(tc.ray_contexts) +
                      " ray contexts (analytic: counted, not timed)"}},
         {{"block", "memory"}, {"instantiated", !m_c.ideal_memory},
          {"why", m_c.ideal_memory ? "ideal_memory: every access hits at L1 latency, no L2/DRAM"
                                   : "functional L1 per unit and shared L2 (tags only), DRAM bytes"}},
        });
    for (int k = 0; k < kOpKindCount; ++k)
        out.instantiated.push_back({{"block", op_kind_name(OpKind(k))},
                                    {"instantiated", uses(OpKind(k))},
                                    {"why", std::string("the ") + accel.kind() + " structure issues " +
                                                (uses(OpKind(k)) ? "" : "no ") + op_kind_name(OpKind(k)) +
                                                " operations (analytic: counted, not timed)"}});
    return out;
}

}  // namespace

AnalyticOutcome run_analytic(const SimConfig& config, const Accel& accel, const MemoryMap& map, RayStream& rays,
                             RaySinkIf& sink) {
    AnalyticModel model(config, accel, map, sink);
    model.run(rays);
    return model.outcome(accel);
}

}  // namespace rtsim
