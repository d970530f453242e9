#include "sim/analytic/sample.h"

#include <algorithm>


namespace rtsim {

SampleProfiler::SampleProfiler(const SimConfig& config, const Accel& accel, const MemoryMap& map, const StepOptions& step,
                               AnalyticProfile& profile)
    : m_c(config),
      m_costs(step_costs(config, accel.op_kinds())),
      m_map(map),
      m_p(profile),
      m_contexts(size_t(config.traversal.units) * config.traversal.contexts()),
      m_ahead(m_contexts.size()),
      m_units(config.traversal.units),
      m_slots(config.traversal.contexts()),
      m_shift(0),
      m_unit_pos(config.traversal.units, 0),
      m_reads(kDataKindCount),
      m_op_sizes(profile.op_sizes.size()) {
    for (Context& ctx : m_contexts) ctx.stepper = accel.make_stepper(step);
    while ((1u << m_shift) < config.l1.line_bytes) ++m_shift;
}

void SampleProfiler::run_cluster(RayStream& stream, uint64_t measure_first, uint64_t measure_end, RaySinkIf& sink) {
    m_measure_first = measure_first;
    m_measure_end = measure_end;
    m_unit_last.clear();
    m_global_last.clear();
    m_global_pos = 0;
    std::fill(m_unit_pos.begin(), m_unit_pos.end(), 0);
    RayDealer dealer(m_c.dispatch, m_units, stream);
    for (uint32_t c = 0; c < m_slots; ++c)
        for (uint32_t u = 0; u < m_units; ++u) start_ray(dealer, u, c, sink);
    // Rounds: every active context takes one step, context-major then unit.
    const size_t n = m_contexts.size();
    auto index = [&](size_t p) { return (p % m_units) * m_slots + p / m_units; };
    // Steps of a few hundred ns against a host miss of about 100 ns (2 and 8 measured alike).
    constexpr size_t kAhead = 4;
    for (bool any = true; any;) {
        any = false;
        for (size_t p = 0; p < n; ++p) {
            prefetch_ahead(index((p + kAhead) % n));
            const size_t i = index(p);
            if (!m_contexts[i].active) continue;
            step(dealer, uint32_t(i / m_slots), uint32_t(i % m_slots), sink);
            any = true;
        }
    }
}

void SampleProfiler::prefetch_ahead(size_t index) const {
    if (!m_contexts[index].active) return;
    const HostAhead& a = m_ahead[index];
    a.prefetch_step();
    if (a.first_fetch() == HostAhead::kNoFetch) return;
    const uint64_t line = a.first_fetch() >> m_shift;
    m_global_last.prefetch(line);
    m_unit_last.prefetch(line << 16 | index / m_slots);
}

bool SampleProfiler::start_ray(RayDealer& dealer, uint32_t unit, uint32_t slot, RaySinkIf& sink) {
    RayJob job;
    Context& ctx = m_contexts[size_t(unit) * m_slots + slot];
    ctx.active = false;
    if (!dealer.next_ray(unit, &job)) return false;
    ctx.stepper->begin(job.ray, job.any_hit ? TraversalMode::any_hit : TraversalMode::closest_hit);
    ctx.id = job.id;
    ctx.stack = StackSplit{};
    ctx.plan_steps = 0;
    ctx.measured = job.id >= m_measure_first && job.id < m_measure_end;
    ctx.active = true;
    m_ahead[size_t(unit) * m_slots + slot].note(*ctx.stepper);
    const Access a = read(unit, m_map.ray(job.id), sizeof(RayRecord), DataKind::ray, ctx.measured);
    if (ctx.measured) m_ray_critical.add(a.key);
    (void)sink;
    return true;
}

void SampleProfiler::finish_ray(Context& ctx, uint32_t unit, uint32_t slot, RaySinkIf& sink) {
    const Stepper& s = *ctx.stepper;
    write(m_map.hit(ctx.id), sizeof(HitRecord), DataKind::hit, ctx.measured);
    sink.ray_done(RayResult{ctx.id, s.hit(), s.work(), 0, 0, unit, slot});
    ++m_p.stepped_rays;
    if (!ctx.measured) return;
    const WorkCounts& w = s.work();
    for (int f = 0; f < kWorkFieldCount; ++f) m_p.sample_work[size_t(f)] += w[WorkField(f)];
    m_p.sample_rays += 1;
    m_p.sample_plan_steps += ctx.plan_steps;
    const double x1 = plan_step_work(w), x2 = w.tri_tests, y = ctx.plan_steps;
    m_fit[0] += x1 * x1, m_fit[1] += x1 * x2, m_fit[2] += x2 * x2, m_fit[3] += x1 * y, m_fit[4] += x2 * y;
}

void SampleProfiler::step(RayDealer& dealer, uint32_t unit, uint32_t slot, RaySinkIf& sink) {
    Context& ctx = m_contexts[size_t(unit) * m_slots + slot];
    Stepper& stepper = *ctx.stepper;
    const StepPlan& plan = stepper.plan();
    if (plan.done) {
        finish_ray(ctx, unit, slot, sink);
        start_ray(dealer, unit, slot, sink);
        return;
    }
    ++ctx.plan_steps;
    StepDemand d;
    take_step(stepper, ctx.stack, m_costs, d);
    // The step's slowest line sets its latency: the one with the longest reuse in the L2's
    // stream (a censored one beats any observed one).
    Access critical;
    for (int i = 0; i < d.read_count; ++i) {
        const Access a = read(unit, d.reads[i].addr, d.reads[i].bytes, d.reads[i].kind, ctx.measured);
        if (i == 0 || a.rank > critical.rank) critical = a;
    }
    if (ctx.measured && d.read_count) m_step_critical.add(critical.key);
    if (ctx.measured)  // tests per operation: the pipelines' widths are applied per configuration
        for (int i = 0; i < d.issue_count; ++i) m_op_sizes[size_t(d.issues[i].kind)].add(d.issues[i].tests);
    stack_traffic(unit, slot, d, ctx.measured);
    m_ahead[size_t(unit) * m_slots + slot].note(stepper);
}

SampleProfiler::Access SampleProfiler::read(uint32_t unit, uint64_t addr, uint32_t bytes, DataKind kind,
                                            bool measured) {
    Access worst;
    bool first = true;
    for_each_line(addr, bytes, m_shift, [&](uint64_t line, uint32_t) {
        const Access a = read_line(unit, line, kind, measured);
        if (first || a.rank > worst.rank) worst = a;
        first = false;
    });
    if (measured) m_p.read_bytes[size_t(kind)] += bytes;
    return worst;
}

SampleProfiler::Access SampleProfiler::read_line(uint32_t unit, uint64_t line, DataKind kind, bool measured) {
    const uint64_t gpos = ++m_global_pos, upos = ++m_unit_pos[unit];
    const uint64_t gprev = m_global_last.exchange(line, gpos);
    const uint64_t uprev = m_unit_last.exchange(line << 16 | unit, upos);
    if (!measured) return {};
    // A distance with no earlier access in the cluster is censored at the access's position.
    const bool gc = gprev == ~0ull, uc = uprev == ~0ull;
    const uint64_t gd = gc ? gpos : gpos - gprev, ud = uc ? upos : upos - uprev;
    const int gb = DistanceBins::bin(gd), ub = DistanceBins::bin(ud);
    (uc ? m_p.unit_censored : m_p.unit_events)[ub] += 1;
    (gc ? m_p.global_censored : m_p.global_events)[gb] += 1;
    const uint32_t key = JointHistogram::pack(ub, uc, gb, gc);
    m_reads[size_t(kind)].add(key);
    return {key, (uint64_t(gc) << 63) | (uint64_t(uc) << 62) | (uint64_t(gb) << 8) | uint64_t(ub)};
}

void SampleProfiler::write(uint64_t addr, uint32_t bytes, DataKind kind, bool measured) {
    if (!measured) return;
    for_each_line(addr, bytes, m_shift, [&](uint64_t, uint32_t part) {
        m_p.writes[size_t(kind)] += 1;
        m_p.write_bytes[size_t(kind)] += double(part);
    });
}

/// The step's stack spills (posted writes) and refills (reads), from its demand.
void SampleProfiler::stack_traffic(uint32_t unit, uint32_t slot, const StepDemand& d, bool measured) {
    const uint32_t bytes = m_costs.stack_entry_bytes;
    const uint64_t owner = uint64_t(unit) * m_slots + slot;
    d.for_each_spill([&](uint32_t s) {
        write(m_map.stack(owner, s, bytes), bytes, DataKind::stack, measured);
        m_p.spill_writes += measured;
    });
    d.for_each_fill([&](uint32_t s) {
        read(unit, m_map.stack(owner, s, bytes), bytes, DataKind::stack, measured);
        m_p.spill_reads += measured;
    });
}

void SampleProfiler::finish() {
    for (size_t k = 0; k < m_reads.size(); ++k)
        m_reads[k].drain([&](uint32_t key, uint64_t n) { m_p.reads[k].add(key, double(n)); });
    for (size_t k = 0; k < m_op_sizes.size(); ++k)
        m_op_sizes[k].drain([&](uint32_t key, uint64_t n) { m_p.op_sizes[k][key] += double(n); });
    m_step_critical.drain([&](uint32_t key, uint64_t n) { m_p.step_critical.add(key, double(n)); });
    m_ray_critical.drain([&](uint32_t key, uint64_t n) { m_p.ray_critical.add(key, double(n)); });
    // Least squares without intercept: plan steps = a (plan-step work) + b tri_tests.
    const double det = m_fit[0] * m_fit[2] - m_fit[1] * m_fit[1];
    if (det > 1e-9 * m_fit[0] * m_fit[2] && det > 0) {
        m_p.plan_steps_per[0] = (m_fit[3] * m_fit[2] - m_fit[4] * m_fit[1]) / det;
        m_p.plan_steps_per[1] = (m_fit[4] * m_fit[0] - m_fit[3] * m_fit[1]) / det;
    } else {
        const double x = AnalyticProfile::plan_step_work(m_p.sample_work);
        m_p.plan_steps_per[0] = x > 0 ? m_p.sample_plan_steps / x : 0.0;
        m_p.plan_steps_per[1] = 0;
    }
}

}  // namespace rtsim
