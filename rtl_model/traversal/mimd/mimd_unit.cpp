#include "rtl_model/traversal/mimd/mimd_unit.h"

#include <algorithm>

namespace rtsim {

MimdUnit::MimdUnit(sc_core::sc_module_name name, const UnitSetup& setup, uint32_t index)
    : ScheduledUnit(name, setup, index, setup.config.contexts(), setup.costs),
      m_treelets(setup.treelets),
      m_contexts(setup.config.contexts()),
      m_ahead(setup.config.contexts()) {
    attach_stack_prefetch(setup.config.contexts());
    SC_THREAD(run);
}

void MimdUnit::run() {
    m_treelet_mode = ray_buffer.size() > 0;
    // Prefetching follows the unit's treelet queue (one stream), or without queues each ray
    // context's entries into treelets (a stream per context).
    if (m_treelets && m_treelets->footprints())
        m_prefetcher.attach(m_treelets->footprints(), m_treelet_mode ? 1 : uint32_t(m_contexts.size()), !m_treelet_mode);
    if (!m_treelet_mode)
        for (Context& ctx : m_contexts) ctx.ray.stepper = m_steppers.acquire();
    Cycle now = 0;
    fill_idle_contexts(0);
    for (;;) {
        if (m_events.empty() && !m_treelet_mode) {
            if (!await_next_release(rays, m_release)) break;  // no ray in flight here
            fill_idle_contexts(now);
            continue;
        }
        if (m_events.empty()) {
            // With treelets, rays may still be parked by other units: look again a little later.
            if (ray_buffer->done()) break;
            now += m_ctx.idle_poll_cycles;
            ++m_idle_polls;
            m_sync(now);
            fill_idle_contexts(now);
            continue;
        }
        const Cycle ready = m_events.top_time();
        const uint32_t c = m_events.begin_pop();
        // The context after this one (unless this one comes back first) runs next: its step's
        // host data is brought in while this event runs.
        const uint32_t after = m_events.runner_up();
        if (after != ContextQueue::kNone) m_ahead[after].prefetch(*mem[0]);
        // The scheduler takes one step per issue_cycles.
        Cycle t = std::max(ready, m_sched_free);
        m_sched_free = t + m_config.issue_cycles;
        now = t;
        // An operations phase on private pipelines touches nothing shared (stack spills sync
        // themselves in stack_traffic()), so it may run ahead of SystemC time.
        if (m_ctx.sync_private_steps || m_contexts[c].phase != Phase::ops) m_sync(t);
        advance(c, t);
        m_events.finish_pop();
        if (!m_events.empty() && m_events.top() != after) m_ahead[m_events.top()].prefetch(*mem[0]);
        if (m_prefetcher.on()) m_prefetcher.drain(*mem[0], t);
        if (m_treelet_mode && t >= m_next_fill) fill_idle_contexts(t);
        if (!m_treelet_mode && rays->releases() != m_release) {  // a frame or held rays were released: fill every context
            if (!m_ctx.sync_private_steps) m_sync(t);  // dispatch is shared: in time order at detailed
            m_release = rays->releases();
            fill_idle_contexts(t);
        }
    }
}

void MimdUnit::fill_idle_contexts(Cycle t) {
    for (uint32_t c = 0; c < m_contexts.size(); ++c)
        if (!m_contexts[c].active && !start_ray(c, t)) break;
    m_next_fill = t + m_ctx.idle_poll_cycles;
}

void MimdUnit::activate(uint32_t c, Cycle t) {
    account(c, CycleUse::starved, t);  // idle until now, while rays were still to come
    m_contexts[c].active = true;
    m_tally.busy.enter(t);
}

void MimdUnit::deactivate(uint32_t c, Cycle t) {
    m_contexts[c].active = false;
    m_tally.busy.leave(t);
}

bool MimdUnit::start_ray(uint32_t c, Cycle t) {
    if (m_treelet_mode) return take_parked_ray(c, t);
    RayJob job;
    if (!rays->next_ray(m_index, &job)) return false;
    t = std::max(t, job.not_before);  // a frame's rays start when the previous frame is done
    Context& ctx = m_contexts[c];
    ctx.ray.stepper->begin(job.ray, job.any_hit ? TraversalMode::any_hit : TraversalMode::closest_hit);
    if (!ray_is_valid(job.ray)) ++m_tally.rejected;
    ctx.ray.ray_id = job.id;
    ctx.ray.start = t;
    ctx.ray.stack = StackSplit{};
    ctx.treelet = kNoTreelet;  // its first step enters one (prefetching without queues)
    m_stack_prefetch.begin(c);
    m_ahead[c].note(*ctx.ray.stepper);
    activate(c, t);
    // The ray record is read from memory before traversal starts.
    const Cycle fetch = t + m_ctx.dispatch_latency;
    account(c, CycleUse::dispatch, fetch);
    AccessInfo info;
    const Cycle ready = mem->access({m_map.ray(job.id), sizeof(RayRecord), false, DataKind::ray, fetch, &info});
    account_read(c, ready, info);
    ctx.phase = Phase::fetch_ray;
    schedule(c, ready);
    return true;
}

bool MimdUnit::take_parked_ray(uint32_t c, Cycle t) {
    Context& ctx = m_contexts[c];
    RayState taken;
    Cycle ready = t;
    if (!ray_buffer->take(m_index, t, &taken, &ctx.treelet, &ready)) return false;
    m_steppers.release(std::move(ctx.ray.stepper));  // the finished ray's stepper is free again
    ctx.ray = std::move(taken);
    const Stepper& s = *ctx.ray.stepper;
    if (s.work().steps == 0 && !ray_is_valid(s.ray())) ++m_tally.rejected;
    ++m_takes;
    if (m_prefetcher.on()) m_prefetcher.enter(0, ctx.treelet, t);
    m_stack_prefetch.begin(c);
    m_ahead[c].note(*ctx.ray.stepper);
    activate(c, t);
    account(c, CycleUse::ray_buffer, ready);
    ctx.phase = Phase::step;
    schedule(c, ready);
    return true;
}

void MimdUnit::park_ray(uint32_t c, uint32_t treelet, Cycle t) {
    ray_buffer->park(treelet, std::move(m_contexts[c].ray), t);
    ++m_parks;
    deactivate(c, t);
    start_ray(c, t);
}

void MimdUnit::advance(uint32_t c, Cycle t) {
    ++m_tally.steps;
    account(c, CycleUse::issue, t);  // ready since its event, waiting for the scheduler
    if (m_contexts[c].phase == Phase::ops) run_ops(c, t);
    else step(c, t);
}

void MimdUnit::step(uint32_t c, Cycle t) {
    Context& ctx = m_contexts[c];
    const StepPlan& plan = ctx.ray.stepper->plan();
    if (plan.done) return finish_ray(c, t);
    if (m_treelets && plan.locality != kNoLocality) {
        const uint32_t target = m_treelets->treelet_of(plan.locality);
        if (target != ctx.treelet) {
            if (m_treelet_mode) return park_ray(c, target, t);  // leaves its treelet
            ctx.treelet = target;  // without queues: the ray walks on into it, prefetched
            if (m_prefetcher.on()) m_prefetcher.enter(c, target, t);
        }
    }
    // The step is costed (and run, with the one arithmetic) as its fetches issue; its
    // operations phase issues what the demand says once the data has arrived.
    // The plan's reads go to memory as the plan holds them, before the step runs; a treelet
    // prefetcher learns the treelet's lines from them.
    StepReads reads(*mem[0], t);
    const bool learning = m_prefetcher.on() && ctx.treelet != kNoTreelet;
    const int stack_before = ctx.ray.stepper->stack_size();
    take_step_reading(*ctx.ray.stepper, ctx.ray.stack, m_costs, ctx.demand, [&](const Fetch& f) {
        if (learning) m_prefetcher.learn(ctx.treelet, f);
        reads.read(f);
    });
    m_stack_prefetch.after_step(c, *ctx.ray.stepper, stack_before);
    m_ahead[c].note(*ctx.ray.stepper);
    account_read(c, reads.ready(), reads.slowest());
    ctx.phase = Phase::ops;
    schedule(c, reads.ready());
}

void MimdUnit::run_ops(uint32_t c, Cycle t) {
    // The step's operations run on their pipelines in order (the plan's, then those its results
    // called for), then spilled stack entries are read back.
    const StepDemand& d = m_contexts[c].demand;
    if (m_stack_prefetch.on()) m_stack_prefetch.issue(c, *mem[0], t);
    Cycle ready = t;
    for (int i = 0; i < d.issue_count; ++i) {
        ready = pipes[size_t(d.issues[i].kind)]->issue(ready, d.issues[i].issues, d.issues[i].tests);
        account(c, pipe_use(d.issues[i].kind), ready);
    }
    if (d.spills || d.fills) {  // most steps move no stack entry to or from memory
        ready = stack_traffic(c, t, ready);
        account(c, CycleUse::stack, ready);  // spilled entries read back after the operations
    }
    m_contexts[c].phase = Phase::step;
    schedule(c, ready);
}

Cycle MimdUnit::stack_traffic(uint32_t c, Cycle t, Cycle ready) {
    const RayState& ray = m_contexts[c].ray;
    const StepDemand& d = m_contexts[c].demand;
    const uint32_t bytes = m_costs.stack_entry_bytes;
    // Spill slots belong to the context (reused ray after ray); with treelets they belong to the
    // ray (its id), since the ray moves between contexts and units through the ray buffer.
    const uint64_t owner = m_treelet_mode ? ray.ray_id : uint64_t(m_index) * m_contexts.size() + c;
    // The write goes on to the shared L2 and a read may miss to it: in time order at detailed.
    return issue_stack_traffic(*mem[0], m_map, d, owner, bytes, t, ready, &m_tally.spill_writes, &m_tally.spill_reads, [&] {
        if (!m_ctx.sync_private_steps) m_sync(t);
    });
}

void MimdUnit::finish_ray(uint32_t c, Cycle t) {
    Context& ctx = m_contexts[c];
    const Stepper& s = *ctx.ray.stepper;
    const RayResult r{ctx.ray.ray_id, s.hit(), s.work(), ctx.ray.start, t, m_index, c, s.mode()};
    m_tally.finish_ray(*mem[0], m_map, r);
    sink->ray_done(r);
    if (m_treelet_mode) ray_buffer->finished(t);
    else rays->ray_finished(t);
    deactivate(c, t);
    start_ray(c, t);
}

CycleAccount MimdUnit::cycle_account(Cycle total_cycles) const {
    return with_tail(m_account, m_contexts, total_cycles);
}

nlohmann::json MimdUnit::stats_json(Cycle total_cycles) const {
    nlohmann::json j;
    StatsWriter w(unit_stats_of("mimd"), j);
    m_tally.write(w, m_sync, cycle_account(total_cycles), total_cycles);
    if (m_treelet_mode) w.set("rays_taken", m_takes).set("rays_parked", m_parks).set("idle_polls", m_idle_polls);
    if (m_prefetcher.on()) w.set("prefetch", m_prefetcher.stats_json());
    if (m_stack_prefetch.on()) w.set("stack_prefetch", m_stack_prefetch.stats_json());
    w.done();
    return j;
}

namespace {

UnitKind mimd_kind() {
    UnitKind k;
    k.name = "mimd";
    k.summary = "each ray context steps on its own, no lock-step (TRaX/STRaTA-style MIMD units, Kopta et al. 2013)";
    k.make_unit = [](const char* name, const UnitSetup& setup, uint32_t index) -> std::unique_ptr<TraversalUnit> {
        return std::make_unique<MimdUnit>(name, setup, index);
    };
    return k;
}

}  // namespace

RTSIM_REGISTER_UNIT_KIND(mimd_kind())

}  // namespace rtsim
