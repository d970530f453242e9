// The exact variant of the analytic level: every ray stepped, every access through functional
// L1s and L2 (tags, LRU, fills in flight) on unloaded per-context clocks, then the closed form
// (closed_form.h). The statistical level (analytic.h) is checked against it
// (tests/cpp/model/test_analytic.cpp); it is slower, not more
// accurate, than the statistical level in the timed levels' terms (docs/fidelity.md).
#include "sim/analytic/analytic.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <memory>
#include <queue>
#include <string>
#include <vector>

#include "rtl_model/dispatch/dispatch.h"
#include "rtl_model/mem/functional_cache.h"
#include "rtl_model/traversal/traversal_unit.h"
#include "sim/analytic/closed_form.h"

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
    AnalyticModel(const SimConfig& config, const Accel& accel, const MemoryMap& map, const StepOptions& step,
                  RaySinkIf& sink)
        : m_c(config), m_costs(step_costs(config, accel.op_kinds())), m_map(map), m_sink(sink), m_ops(accel.op_kinds()), m_units(config.traversal.units),
          m_contexts(size_t(config.traversal.units) * config.traversal.contexts()) {
        for (Context& ctx : m_contexts) ctx.stepper = accel.make_stepper(step);
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
        StackSplit stack;
        bool active = false;
    };
    bool start_ray(uint32_t unit, uint32_t slot);
    void step(uint32_t unit, uint32_t slot);
    Cycle read(uint32_t unit, uint64_t addr, uint32_t bytes, DataKind kind, Cycle now);
    void write(uint32_t unit, uint64_t addr, uint32_t bytes, DataKind kind);
    Cycle stack_traffic(uint32_t unit, uint32_t slot, const StepDemand& d, Cycle now);
    Cycle pipe(uint32_t unit, const OpIssue& op);
    bool uses(OpKind kind) const { return std::find(m_ops.begin(), m_ops.end(), kind) != m_ops.end(); }
    AnalyticDemands demands() const;

    const SimConfig& m_c;
    const StepCosts m_costs;
    const MemoryMap& m_map;
    RaySinkIf& m_sink;
    std::vector<OpKind> m_ops;  ///< operation kinds the structure issues
    std::vector<UnitCounts> m_units;
    std::vector<Context> m_contexts;  ///< unit-major: unit * ray_contexts + context
    std::vector<FunctionalCache> m_l1;
    std::unique_ptr<FunctionalCache> m_l2;
    MemStats m_dram, m_ideal;
    uint32_t m_line_bytes = 64;
    std::unique_ptr<RayDealer> m_dispatch;  ///< the model's dispatch policy: same ray-to-unit assignment
    uint64_t m_dispatched = 0;
    double m_latency_sum = 0;
    Cycle m_latency_max = 0;
    double m_l1_hold = 0, m_l2_hold = 0;  ///< cycles L1 / L2 misses hold an MSHR, summed
};

void AnalyticModel::run(RayStream& rays) {
    m_dispatch = std::make_unique<RayDealer>(m_c.dispatch, m_c.traversal.units, rays);
    const uint32_t units = m_c.traversal.units, contexts = m_c.traversal.contexts();
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
    Context& ctx = m_contexts[size_t(unit) * m_c.traversal.contexts() + slot];
    ctx.stepper->begin(job.ray, job.any_hit ? TraversalMode::any_hit : TraversalMode::closest_hit);
    if (!ray_is_valid(job.ray)) ++m_units[unit].rejected;
    ctx.id = job.id;
    ctx.stack = StackSplit{};
    ctx.active = true;
    m_units[unit].steps += kSchedulerSlotsPerRay;  // the ray-fetch step (and the end)
    ctx.start = ctx.clock;
    const Cycle fetch = ctx.clock + m_c.dispatch.latency;
    ctx.clock = fetch + read(unit, m_map.ray(job.id), sizeof(RayRecord), DataKind::ray, fetch);
    return true;
}

void AnalyticModel::step(uint32_t unit, uint32_t slot) {
    Context& ctx = m_contexts[size_t(unit) * m_c.traversal.contexts() + slot];
    UnitCounts& uc = m_units[unit];
    Stepper& stepper = *ctx.stepper;
    const StepPlan& plan = stepper.plan();
    if (plan.done) {
        write(unit, m_map.hit(ctx.id), sizeof(HitRecord), DataKind::hit);  // posted
        const Cycle latency = ctx.clock - ctx.start;
        m_sink.ray_done(RayResult{ctx.id, stepper.hit(), stepper.work(), 0, latency, unit, slot, stepper.mode()});
        ++uc.rays;
        m_latency_sum += double(latency);
        m_latency_max = std::max(m_latency_max, latency);
        ctx.active = false;
        start_ray(unit, slot);
        return;
    }
    // The step as the traversal unit takes it (the step-demand function): its fetches, then its
    // operations in order, then the stack entries read back.
    StepDemand d;
    take_step(stepper, ctx.stack, m_costs, d);
    uc.steps += d.scheduler_slots;
    Cycle fetched = 0;
    for (int i = 0; i < d.read_count; ++i)
        fetched = std::max(fetched, read(unit, d.reads[i].addr, d.reads[i].bytes, d.reads[i].kind, ctx.clock));
    ctx.clock += fetched;
    Cycle ready = 0;
    for (int i = 0; i < d.issue_count; ++i) ready += pipe(unit, d.issues[i]);
    ctx.clock += std::max(ready, stack_traffic(unit, slot, d, ctx.clock));
}

/// Issues an operation into its pipeline; returns its unloaded latency.
Cycle AnalyticModel::pipe(uint32_t unit, const OpIssue& op) {
    const PipelineConfig& pc = m_c.pipeline(op.kind);
    m_units[unit].issues[size_t(op.kind)] += op.issues;
    m_units[unit].tests[size_t(op.kind)] += op.tests;
    return op.issues ? Cycle(op.issues - 1) * pc.initiation_interval + pc.latency : 0;
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
    for_each_line(addr, bytes, shift, [&](uint64_t line, uint32_t part) {
        const Cycle l1_tag = now + m_c.l1.latency;
        Cycle ready = 0, *fill = nullptr;
        if (m_l1[unit].read(line, part, kind, l1_tag, &ready, &fill)) {
            done = std::max(done, std::max(l1_tag, ready));
            return;
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
    });
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
    for_each_line(addr, bytes, shift, [&](uint64_t, uint32_t part) {
        m_l1[unit].write(part, kind);
        m_l2->write(part, kind);
        ++m_dram[kind].writes;
        m_dram[kind].write_bytes += part;
    });
}

/// The step's stack spills (posted writes) and refills (reads the ray waits for), from its
/// demand; returns the refill latency.
Cycle AnalyticModel::stack_traffic(uint32_t unit, uint32_t slot, const StepDemand& d, Cycle now) {
    const uint32_t bytes = m_costs.stack_entry_bytes;
    const uint64_t owner = uint64_t(unit) * m_c.traversal.contexts() + slot;
    Cycle refill = 0;
    d.for_each_spill([&](uint32_t s) {
        write(unit, m_map.stack(owner, s, bytes), bytes, DataKind::stack);
        ++m_units[unit].spill_writes;
    });
    d.for_each_fill([&](uint32_t s) {
        ++m_units[unit].spill_reads;
        refill = std::max(refill, read(unit, m_map.stack(owner, s, bytes), bytes, DataKind::stack, now));
    });
    return refill;
}

/// The demands of the closed form (sim/analytic/closed_form.h) from this model's counts.
AnalyticDemands AnalyticModel::demands() const {
    AnalyticDemands d;
    d.rays = double(m_dispatched);
    for (const UnitCounts& u : m_units) {
        for (int k = 0; k < kOpKindCount; ++k) d.issues[k] += double(u.issues[k]);
        d.scheduler_steps += double(u.steps);
    }
    if (!m_c.ideal_memory) {
        const MemCounters dram = m_dram.total(), l2 = m_l2->stats().total();
        for (const FunctionalCache& l1 : m_l1) d.l1_accesses += double(l1.stats().total().reads + l1.stats().total().writes);
        d.l2_accesses = double(l2.reads + l2.writes);
        d.dram_bytes = double(dram.read_bytes + dram.write_bytes);
        d.l1_hold = m_l1_hold;
        d.l2_hold = m_l2_hold;
    }
    d.latency_sum = m_latency_sum;
    d.latency_max = double(m_latency_max);
    return d;
}

AnalyticOutcome AnalyticModel::outcome(const Accel& accel) const {
    AnalyticOutcome out;
    const AnalyticDemands d = demands();
    const ClosedForm form = closed_form(m_c, m_ops, d);
    out.cycles = Cycle(form.cycles);
    const double total = form.cycles;
    std::vector<std::vector<double>> issues(m_units.size(), std::vector<double>(kOpKindCount)), tests = issues;
    for (size_t u = 0; u < m_units.size(); ++u)
        for (int k = 0; k < kOpKindCount; ++k) issues[u][k] = double(m_units[u].issues[k]), tests[u][k] = double(m_units[u].tests[k]);
    json& m = out.model;
    m = pipelines_json(m_c, m_ops, issues, tests, total);
    m["dispatch"] = m_dispatch->stats_json();
    for (size_t u = 0; u < m_units.size(); ++u) {
        const UnitCounts& uc = m_units[u];
        StatsWriter(unit_stats(), m["units"]["tu" + std::to_string(u)])
            .set("rays", uc.rays)
            .set("steps", uc.steps)
            .set("stack_spill_writes", uc.spill_writes)
            .set("stack_spill_reads", uc.spill_reads)
            .set("rejected_rays", uc.rejected)
            .untimed()
            .done();
    }
    if (m_c.ideal_memory) {
        StatsWriter(ideal_memory_stats(), m["ideal_memory"]).merge(m_ideal.to_json()).done();
    } else {
        for (size_t u = 0; u < m_l1.size(); ++u) m["l1"]["l1_" + std::to_string(u)] = m_l1[u].stats_json();
        m["l2"] = m_l2->stats_json();
        StatsWriter w(dram_stats(), m["dram"]);
        w.merge(dram_counters_json(m_dram));
        dram_bandwidth_stats(w, m_c.dram, d.dram_bytes, total, m_c.clock_ghz);
        w.set("bandwidth_over_time", json::array()).untimed().done();
    }
    StatsWriter(analytic_stats(), m["analytic"])
        .merge(closed_form_json(form, d))
        .set("caches", "functional")
        .set("assignment", "rays to contexts in trace order as contexts free up; the context with the earliest "
                           "unloaded clock steps next")
        .done();
    out.instantiated = analytic_instantiated(m_c, accel.kind(), m_ops,
                                             "functional L1 per unit and shared L2 (tags only), DRAM bytes");
    return out;
}

}  // namespace

AnalyticOutcome run_analytic_exact(const SimConfig& config, const Accel& accel, const MemoryMap& map,
                                   const StepOptions& step, RayStream& rays, RaySinkIf& sink) {
    AnalyticModel model(config, accel, map, step, sink);
    model.run(rays);
    return model.outcome(accel);
}

}  // namespace rtsim
