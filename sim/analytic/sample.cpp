#include "sim/analytic/sample.h"

#include <algorithm>

#include "rtl_model/common/ray_state.h"
#include "rtl_model/common/round_windows.h"
#include "sim/analytic/round_waits.h"


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
      m_unit_pos(config.traversal.units + 1, 0),  // + the ray buffer's admission stream
      m_reads(kDataKindCount),
      m_op_sizes(profile.op_sizes.size()),
      m_accel(&accel),
      m_step(step),
      m_merges(!config.traversal.kind().group_profile) {
    for (Context& ctx : m_contexts) ctx.stepper = accel.make_stepper(step);
    while ((1u << m_shift) < config.l1.line_bytes) ++m_shift;
    const TreeletConfig& t = config.treelets;
    if (!t.enabled) return;
    m_partition = std::make_unique<LocalityPartition>(accel.partition(uint64_t(t.treelet_kib) * 1024));
    m_queues.resize(m_partition->treelets.size());
    m_unit_treelet.assign(m_units, -1);
    const uint32_t state = ray_state_bytes(config.traversal.stack_entries, config.traversal.stack_entry_bytes,
                                           config.mailbox.entries * MailboxConfig::kEntryBytes);
    m_capacity = std::max<uint64_t>(1, uint64_t(t.buffer_kib) * 1024 / state);
    m_admit_limit = t.max_rays_in_flight ? t.max_rays_in_flight : m_capacity + m_contexts.size();
    for (Context& ctx : m_contexts) m_free.push_back(std::move(ctx.stepper));  // steppers move with rays
}

void SampleProfiler::run_cluster(RayStream& stream, uint64_t measure_first, uint64_t measure_end, RaySinkIf& sink) {
    m_measure_first = measure_first;
    m_measure_end = measure_end;
    m_unit_last.clear();
    m_global_last.clear();
    m_global_pos = 0;
    std::fill(m_unit_pos.begin(), m_unit_pos.end(), 0);
    RayDealer dealer(m_c.dispatch, m_units, stream);
    // The phases are the run's only when one cluster holds the whole trace from its first ray.
    m_record_phases = ++m_clusters_run == 1 && measure_first == 0 && measure_end >= stream.total_rays();
    m_phases.clear();
    m_window_rounds = 1;
    if (m_record_phases) m_phases.emplace_back();
    if (m_partition) return run_treelets(dealer, sink);
    for (uint32_t c = 0; c < m_slots; ++c)
        for (uint32_t u = 0; u < m_units; ++u) start_ray(dealer, u, c, sink);
    // Rounds: every active context takes one step, context-major then unit, unless it still
    // waits for its last step's line (wait_rounds).
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
            if (m_contexts[i].wait) --m_contexts[i].wait;
            else step(dealer, uint32_t(i / m_slots), uint32_t(i % m_slots), sink);
            any = true;
            if (m_record_phases) m_phases.back().contexts += 1;  // busy this round, stepping or not
        }
        if (any && m_record_phases) end_round();
    }
}

void SampleProfiler::end_round() {
    end_window_round(m_phases, &m_window_rounds, AnalyticProfile::kMaxPhaseWindows,
                     [](PhaseCounts& into, PhaseCounts& other) {
                         into.rounds += other.rounds, into.steps += other.steps, into.contexts += other.contexts;
                         other.reads.drain([&](uint32_t key, uint64_t n) { into.reads.add(key, n); });
                         other.critical.drain([&](uint32_t key, uint64_t n) { into.critical.add(key, n); });
                     });
}

void SampleProfiler::run_treelets(RayDealer& dealer, RaySinkIf& sink) {
    for (auto& q : m_queues) q.clear();
    m_by_size.clear();
    m_nonempty.clear();
    std::fill(m_unit_treelet.begin(), m_unit_treelet.end(), -1);
    m_in_machine = m_waiting = 0;
    admit(dealer);
    const size_t n = m_contexts.size();
    auto index = [&](size_t p) { return (p % m_units) * m_slots + p / m_units; };
    // Rounds as without treelets, waits included: every context with a ray takes one step; an
    // idle one takes a ray of its unit's treelet first (other units' parks refill the queues).
    for (bool any = true; any;) {
        any = false;
        for (size_t p = 0; p < n; ++p) {
            const size_t i = index(p);
            const uint32_t unit = uint32_t(i / m_slots), slot = uint32_t(i % m_slots);
            if (!m_contexts[i].active && !take_ray(unit, slot)) continue;
            if (m_contexts[i].wait) --m_contexts[i].wait;
            else step(dealer, unit, slot, sink);
            any = true;
            if (m_record_phases) m_phases.back().contexts += 1;
        }
        if (any && m_record_phases) end_round();
    }
}

void SampleProfiler::admit(RayDealer& dealer) {
    // As the ray buffer admits (ray_buffer.cpp, has_room): below the limit and, without an
    // explicit one, only while the SRAM has room (one entry kept free for a park), so it never
    // overflows.
    const bool may_overflow = m_c.treelets.max_rays_in_flight != 0;
    const uint64_t reserve = m_capacity > 1 ? 1 : 0;
    RayJob job;
    while (m_in_machine < m_admit_limit && (may_overflow || m_waiting + reserve < m_capacity) &&
           dealer.next_ray(RaySourceIf::kAnyUnit, &job)) {
        Ray r;
        if (m_free.empty()) {
            r.stepper = m_accel->make_stepper(m_step);
        } else {
            r.stepper = std::move(m_free.back());
            m_free.pop_back();
        }
        r.stepper->begin(job.ray, job.any_hit ? TraversalMode::any_hit : TraversalMode::closest_hit);
        r.id = job.id;
        r.measured = job.id >= m_measure_first && job.id < m_measure_end;
        // The ray buffer reads the record as it admits the ray: the shared stream only.
        const Access a = read(m_units, m_map.ray(job.id), sizeof(RayRecord), DataKind::ray, r.measured);
        if (r.measured) m_ray_critical.add(a.key);
        const uint32_t first = r.stepper->plan().locality;
        park(std::move(r), first == kNoLocality ? m_partition->root_group : m_partition->group_of[first]);
        ++m_in_machine;
    }
}

int64_t SampleProfiler::pick() const {
    // As the ray buffer's scheduler: the largest queue (the lowest index of equal ones), or round
    // robin from the last pick; the oldest front is judged as the largest here.
    if (m_nonempty.empty()) return -1;
    if (m_c.treelets.policy == TreeletPolicy::round_robin) {
        auto it = m_nonempty.upper_bound(m_round_robin);
        return int64_t(it == m_nonempty.end() ? *m_nonempty.begin() : *it);
    }
    return int64_t(m_by_size.begin()->second);
}

void SampleProfiler::resize_queue_index(uint32_t t, int64_t delta) {
    const int64_t before = int64_t(m_queues[t].size()) - delta;
    if (before > 0) m_by_size.erase({-before, t});
    if (m_queues[t].empty()) {
        m_nonempty.erase(t);
        return;
    }
    m_by_size.insert({-int64_t(m_queues[t].size()), t});
    m_nonempty.insert(t);
}

bool SampleProfiler::take_ray(uint32_t unit, uint32_t slot) {
    int64_t& current = m_unit_treelet[unit];
    if (current < 0 || m_queues[size_t(current)].empty()) {
        current = pick();
        if (current < 0) return false;
        m_round_robin = uint32_t(current);
    }
    Context& ctx = m_contexts[size_t(unit) * m_slots + slot];
    if (ctx.stepper) m_free.push_back(std::move(ctx.stepper));
    static_cast<Ray&>(ctx) = std::move(m_queues[size_t(current)].front());
    m_queues[size_t(current)].pop_front();
    resize_queue_index(uint32_t(current), -1);
    --m_waiting;
    ctx.treelet = uint32_t(current);
    ctx.active = true;
    if (ctx.measured) m_p.treelet_takes += 1;
    m_ahead[size_t(unit) * m_slots + slot].note(*ctx.stepper);
    return true;
}

void SampleProfiler::park(Ray&& ray, uint32_t treelet) {
    // Beyond the SRAM's rays a queued ray's state overflows to memory (written, read back).
    if (m_waiting >= m_capacity && ray.measured) m_p.treelet_overflows += 1;
    m_queues[treelet].push_back(std::move(ray));
    resize_queue_index(treelet, +1);
    ++m_waiting;
}

void SampleProfiler::prefetch_ahead(size_t index) const {
    if (!m_contexts[index].active || m_contexts[index].wait) return;  // it does not step this round
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
    sink.ray_done(RayResult{ctx.id, s.hit(), s.work(), 0, 0, unit, slot, s.mode()});
    ++m_p.stepped_rays;
    if (!ctx.measured) return;
    const WorkCounts& w = s.work();
    for (int f = 0; f < kWorkFieldCount; ++f) m_p.sample_work[size_t(f)] += w[WorkField(f)];
    m_p.sample_rays += 1;
    m_p.sample_plan_steps += ctx.plan_steps;
    const double x1 = plan_step_work(w), x2 = double(w.tri_tests) + double(w.sphere_tests) + double(w.capsule_tests), y = ctx.plan_steps;
    m_fit[0] += x1 * x1, m_fit[1] += x1 * x2, m_fit[2] += x2 * x2, m_fit[3] += x1 * y, m_fit[4] += x2 * y;
}

void SampleProfiler::step(RayDealer& dealer, uint32_t unit, uint32_t slot, RaySinkIf& sink) {
    Context& ctx = m_contexts[size_t(unit) * m_slots + slot];
    Stepper& stepper = *ctx.stepper;
    const StepPlan& plan = stepper.plan();
    if (plan.done) {
        finish_ray(ctx, unit, slot, sink);
        if (m_partition) {  // the ray leaves the machine: room for another
            ctx.active = false;
            --m_in_machine;
            admit(dealer);
            take_ray(unit, slot);
            return;
        }
        start_ray(dealer, unit, slot, sink);
        return;
    }
    if (m_partition && plan.locality != kNoLocality && m_partition->group_of[plan.locality] != ctx.treelet) {
        // It leaves its treelet: parked in the other's queue; the context takes the next ray.
        if (ctx.measured) m_p.treelet_parks += 1;
        park(std::move(static_cast<Ray&>(ctx)), m_partition->group_of[plan.locality]);
        ctx.active = false;
        take_ray(unit, slot);
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
    // Rounds as time: a step whose slowest line is likely served below the L1 holds its context
    // for the rounds that takes (wait_rounds), so the rays left at the end are the slow ones.
    if (d.read_count) ctx.wait = wait_rounds(critical.key);
    if (m_record_phases) {
        PhaseCounts& w = m_phases.back();
        w.steps += 1;
        if (d.read_count) w.critical.add(MergeKey::octaves(critical.key));
    }
    if (ctx.measured && d.read_count) {
        m_step_critical.add(critical.key);
        if (m_merges && critical.merge_l1) m_p.merge_l1[critical.merge_l1_key] += 1;
        if (m_merges && critical.merge_l2) m_p.merge_l2[critical.merge_l2_key] += 1;
    }
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

namespace {

/// A stream's last read of a line, packed in its LastUse slot: the read's position, and the run of
/// close reads it is in (MergeKey): the gap from the run's first read and that read's joint key.
struct LastRead {
    uint64_t pos = 0, gap = 0;
    uint32_t head_key = 0;
    static LastRead from(uint64_t v) { return {v >> 32, (v >> 18) & 0x3FFF, uint32_t(v & 0x3FFFF)}; }
    uint64_t packed() const { return pos << 32 | gap << 18 | head_key; }
};

/// The run the read at `pos` joins (in_run) or begins, given the line's previous read.
LastRead next_run(bool found, const LastRead& prev, uint64_t pos, uint32_t key, bool* in_run) {
    const uint64_t gap = found ? prev.gap + (pos - prev.pos) : MergeKey::kRunAccesses;
    *in_run = gap < MergeKey::kRunAccesses;
    return *in_run ? LastRead{pos, gap, prev.head_key} : LastRead{pos, 0, key};
}

}  // namespace

SampleProfiler::Access SampleProfiler::read_line(uint32_t unit, uint64_t line, DataKind kind, bool measured) {
    const uint64_t gpos = ++m_global_pos, upos = ++m_unit_pos[unit];
    bool gfound, ufound;
    uint64_t& gslot = m_global_last.slot(line, gfound);
    uint64_t& uslot = m_unit_last.slot(line << 16 | unit, ufound);
    const LastRead gprev = LastRead::from(gfound ? gslot : 0), uprev = LastRead::from(ufound ? uslot : 0);
    // A distance with no earlier access in the cluster is censored at the access's position.
    const bool gc = !gfound, uc = !ufound;
    const uint64_t gd = gc ? gpos : gpos - gprev.pos, ud = uc ? upos : upos - uprev.pos;
    const int gb = DistanceBins::bin(gd), ub = DistanceBins::bin(ud);
    const uint32_t key = JointHistogram::pack(ub, uc, gb, gc);
    Access a;
    const LastRead gnext = next_run(gfound, gprev, gpos, key, &a.merge_l2);
    const LastRead unext = next_run(ufound, uprev, upos, key, &a.merge_l1);
    gslot = gnext.packed(), uslot = unext.packed();
    if (!measured) return {};
    (uc ? m_p.unit_censored : m_p.unit_events)[ub] += 1;
    (gc ? m_p.global_censored : m_p.global_events)[gb] += 1;
    m_reads[size_t(kind)].add(key);
    if (m_record_phases) m_phases.back().reads.add(MergeKey::octaves(key));
    if (!m_frame_reads.empty()) m_frame_reads.back().second.add(MergeKey::octaves(key));
    a.key = key;
    a.rank = (uint64_t(gc) << 63) | (uint64_t(uc) << 62) | (uint64_t(gb) << 8) | uint64_t(ub);
    // The L1's merge asks of the read only whether it hits the L1 (its unit-stream bin).
    if (a.merge_l1) a.merge_l1_key = MergeKey::pack(JointHistogram::pack(ub, uc, 0, false), unext.head_key, DistanceBins::bin(unext.gap));
    if (a.merge_l2) a.merge_l2_key = MergeKey::pack(key, gnext.head_key, DistanceBins::bin(gnext.gap));
    return a;
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

void SampleProfiler::begin_frame_sample(uint32_t frame) { m_frame_reads.emplace_back(frame, KeyCounts{}); }

void SampleProfiler::finish() {
    m_p.frame_samples.clear();
    for (auto& [frame, counts] : m_frame_reads) {
        FrameSample& f = m_p.frame_samples.emplace_back();
        f.frame = frame;
        counts.drain([&](uint32_t key, uint64_t n) { f.reads.add(key, double(n)); });
    }
    for (size_t k = 0; k < m_reads.size(); ++k)
        m_reads[k].drain([&](uint32_t key, uint64_t n) { m_p.reads[k].add(key, double(n)); });
    for (size_t k = 0; k < m_op_sizes.size(); ++k)
        m_op_sizes[k].drain([&](uint32_t key, uint64_t n) { m_p.op_sizes[k][key] += double(n); });
    m_step_critical.drain([&](uint32_t key, uint64_t n) { m_p.step_critical.add(key, double(n)); });
    m_ray_critical.drain([&](uint32_t key, uint64_t n) { m_p.ray_critical.add(key, double(n)); });
    m_p.phases.clear();
    m_p.phase_units = m_units, m_p.phase_contexts = m_slots;
    if (m_clusters_run == 1)
        for (PhaseCounts& w : m_phases) {
            if (w.rounds == 0) continue;
            PhaseWindow& out = m_p.phases.emplace_back();
            out.rounds = w.rounds, out.steps = w.steps, out.contexts = w.contexts;
            w.reads.drain([&](uint32_t key, uint64_t n) { out.reads.add(key, double(n)); });
            w.critical.drain([&](uint32_t key, uint64_t n) { out.critical.add(key, double(n)); });
        }
    // Least squares without intercept: plan steps = a (plan-step work) + b primitive tests
    // (triangles', spheres' and capsules').
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
