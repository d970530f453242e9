#include "rtl_model/traversal/simt/simt_unit.h"
#include "rtl_model/traversal/simt/simt_profile.h"

#include <algorithm>
#include <array>

namespace rtsim {

SimtUnit::SimtUnit(sc_core::sc_module_name name, const UnitSetup& setup, uint32_t index)
    : ScheduledUnit(name, setup, index, setup.config.groups(), setup.costs),
      m_simt(setup.config.kind_config<SimtConfig>()),
      m_treelets(setup.treelets),
      m_lanes(setup.config.groups() * m_simt.lanes),
      m_warps(setup.config.groups()),
      m_coalescer(setup.context.line_bytes),
      m_active_histogram(m_simt.lanes + 1, 0) {
    attach_stack_prefetch(uint32_t(m_lanes.size()));
    SC_THREAD(run);
}

void SimtUnit::run() {
    m_treelet_mode = ray_buffer.size() > 0;
    m_walks = m_simt.cooperative && !m_treelet_mode;
    // Prefetching follows each warp's treelet queue (a stream per warp), or without queues each
    // lane's entries into treelets (a stream per lane; treelet_prefetcher.h).
    if (m_treelets && m_treelets->footprints())
        m_prefetcher.attach(m_treelets->footprints(), m_treelet_mode ? uint32_t(m_warps.size()) : uint32_t(m_lanes.size()),
                            !m_treelet_mode);
    if (!m_treelet_mode)
        for (Lane& lane : m_lanes) lane.ray.stepper = m_steppers.acquire();
    Cycle now = 0;
    fill_idle_warps(0);
    for (;;) {
        if (m_events.empty() && !m_treelet_mode) {
            if (!await_next_release(rays, m_release)) break;  // no warp has a ray
            fill_idle_warps(now);
            continue;
        }
        if (m_events.empty()) {
            // With treelets, rays may still be parked by other units: look again a little later.
            if (ray_buffer->done()) break;
            now += m_ctx.idle_poll_cycles;
            ++m_idle_polls;
            m_sync(now);
            fill_idle_warps(now);
            continue;
        }
        const Cycle ready = m_events.top_time();
        const uint32_t w = m_events.begin_pop();
        // The scheduler issues one warp phase per issue_cycles.
        const Cycle t = std::max(ready, m_sched_free);
        m_sched_free = t + m_config.issue_cycles;
        now = t;
        m_sync(t);
        advance(w, t);
        m_events.finish_pop();
        if (m_prefetcher.on()) m_prefetcher.drain(*mem[0], t);
        if (m_treelet_mode) {
            if (t >= m_next_fill) fill_when_idle(t);
        } else if (rays->releases() != m_release) {  // a frame or held rays were released: fill the idle warps
            m_release = rays->releases();
            fill_idle_warps(t);
        }
    }
}

void SimtUnit::fill_when_idle(Cycle t) {
    fill_idle_warps(t);
    m_next_fill = t + m_ctx.idle_poll_cycles;
}

bool SimtUnit::warp_has_ray(uint32_t w) const {
    for (uint32_t l = first_lane(w); l < first_lane(w) + m_simt.lanes; ++l)
        if (m_lanes[l].has_ray) return true;
    return false;
}

void SimtUnit::fill_idle_warps(Cycle t) {
    for (uint32_t w = 0; w < m_warps.size(); ++w) {
        if (warp_has_ray(w)) continue;  // in flight: it refills itself
        if (!retire_and_refill(w, t)) break;  // dispatch has nothing now
        fetch_rays(w, t);
    }
}

void SimtUnit::advance(uint32_t w, Cycle t) {
    ++m_tally.steps;
    if (m_warps[w].phase == Phase::ops) run_ops(w, t);
    else step(w, t);
}

bool SimtUnit::retire_and_refill(uint32_t w, Cycle t) {
    m_coalescer.clear();
    const uint32_t end = first_lane(w) + m_simt.lanes;
    bool any_ray = false;
    for (uint32_t l = first_lane(w); l < end; ++l) {
        m_lanes[l].stepping = false;
        m_lanes[l].helps = kNoLane;
        if (m_lanes[l].has_ray && ray_done(l)) finish_lane(l, t);
        any_ray = any_ray || m_lanes[l].has_ray;
    }
    if (m_simt.refill == SimtRefill::warp && any_ray) return false;  // the warp has not retired
    Cycle fetch = 0;
    bool taken = false;
    for (uint32_t l = first_lane(w); l < end; ++l)
        if (!m_lanes[l].has_ray) {
            // Treelet scheduling: a warp is formed from one treelet queue's rays; it moves to
            // another queue only once it holds no ray.
            const bool ok = m_treelet_mode ? take_lane(w, l, t, !any_ray && !taken, &fetch) : start_lane(l, t, &fetch);
            if (!ok) break;
            taken = true;
        }
    m_fetch_at = fetch;
    return taken;
}

bool SimtUnit::take_lane(uint32_t w, uint32_t l, Cycle t, bool may_switch, Cycle* fetch) {
    Lane& lane = m_lanes[l];
    RayState taken;
    uint32_t treelet = 0;
    Cycle ready = t;
    const uint32_t consumer = m_index * uint32_t(m_warps.size()) + w;
    if (!ray_buffer->take(consumer, t, &taken, &treelet, &ready, may_switch)) return false;
    m_steppers.release(std::move(lane.ray.stepper));  // the finished ray's stepper is free again
    lane.ray = std::move(taken);
    const Stepper& s = *lane.ray.stepper;
    if (s.work().steps == 0 && !ray_is_valid(s.ray())) ++m_tally.rejected;
    ++m_takes;
    if (m_warps[w].treelet != treelet && m_prefetcher.on()) m_prefetcher.enter(w, treelet, t);
    m_warps[w].treelet = treelet;
    account_until(m_account, lane.accounted, CycleUse::starved, t);  // no ray until now
    lane.has_ray = lane.stepping = true;
    lane.ready = ready;
    m_stack_prefetch.begin(l);
    m_tally.busy.enter(t);
    *fetch = std::max(*fetch, ready);
    return true;
}

void SimtUnit::park_leavers(uint32_t w, Cycle t) {
    for (uint32_t l = first_lane(w); l < first_lane(w) + m_simt.lanes; ++l) {
        Lane& lane = m_lanes[l];
        if (!lane.has_ray) continue;
        const StepPlan& plan = lane.ray.stepper->plan();
        if (plan.done || plan.locality == kNoLocality) continue;
        const uint32_t target = m_treelets->treelet_of(plan.locality);
        if (target == m_warps[w].treelet) continue;
        account_until(m_account, lane.accounted, CycleUse::issue, t);
        ray_buffer->park(target, std::move(lane.ray), t);
        ++m_parks;
        lane.has_ray = false;
        m_tally.busy.leave(t);
    }
}

void SimtUnit::note_treelet(uint32_t l, Cycle t) {
    Lane& lane = m_lanes[l];
    const StepPlan& plan = lane.ray.stepper->plan();
    if (plan.locality == kNoLocality) return;
    const uint32_t treelet = m_treelets->treelet_of(plan.locality);
    if (treelet == lane.treelet) return;
    lane.treelet = treelet;
    m_prefetcher.enter(l, treelet, t);
}

bool SimtUnit::start_lane(uint32_t l, Cycle t, Cycle* fetch) {
    RayJob job;
    if (!rays->next_ray(m_index, &job)) return false;
    const Cycle start = std::max(t, job.not_before);  // a frame's rays start when the previous frame is done
    Lane& lane = m_lanes[l];
    lane.ray.stepper->begin(job.ray, job.any_hit ? TraversalMode::any_hit : TraversalMode::closest_hit);
    if (!ray_is_valid(job.ray)) ++m_tally.rejected;
    lane.ray.ray_id = job.id;
    lane.ray.kind = job.kind;
    lane.ray.start = start;
    lane.ray.stack = StackSplit{};
    lane.treelet = kNoTreelet;
    m_stack_prefetch.begin(l);
    // Cooperative lanes: the ray's walk is stepped ahead now, as a tree of steps (cooperation.h).
    if (m_walks) lane.walk.record(*lane.ray.stepper, lane.ray.stack, &m_costs, m_config.stack_prefetch);
    account_until(m_account, lane.accounted, CycleUse::starved, start);  // no ray until now
    lane.has_ray = lane.stepping = true;
    m_tally.busy.enter(start);
    *fetch = std::max(*fetch, start + m_ctx.dispatch_latency);
    m_coalescer.add(m_map.ray(job.id), sizeof(RayRecord), DataKind::ray);
    return true;
}

void SimtUnit::fetch_rays(uint32_t w, Cycle t) {
    // The new rays' records are read (coalesced) in a warp step of their own, or with treelet
    // scheduling their states come from the ray buffer's SRAM; the lanes that already had rays
    // wait for it.
    AccessInfo slowest;
    const Cycle ready = m_treelet_mode ? m_fetch_at : issue_reads(m_fetch_at, &slowest);
    for (uint32_t l = first_lane(w); l < first_lane(w) + m_simt.lanes; ++l) {
        Lane& lane = m_lanes[l];
        if (!lane.stepping) continue;
        if (m_treelet_mode) {
            account_until(m_account, lane.accounted, CycleUse::ray_buffer, lane.ready);
            account_until(m_account, lane.accounted, CycleUse::issue, ready);  // the warp's slowest state
            continue;
        }
        account_until(m_account, lane.accounted, CycleUse::dispatch, m_fetch_at);
        account_read_until(m_account, lane.accounted, ready, slowest);
    }
    account_idle(w, ready);
    count_warp_step(w, t);
    ++m_fetch_steps;
    m_warps[w].phase = Phase::step;
    m_events.schedule(w, std::max(ready, t));
}

uint32_t SimtUnit::choose_class(uint32_t w) const {
    std::array<uint32_t, kClasses> want{};
    bool any = false;
    for (uint32_t l = first_lane(w); l < first_lane(w) + m_simt.lanes; ++l)
        if (m_lanes[l].has_ray) {
            ++want[lane_class(l)];
            any = true;
        }
    if (!any) return kClasses;
    const uint32_t last = m_warps[w].last_class;
    // while-while stays in its inner loop while any lane needs it; both policies then take the
    // next kind in program order that some lane needs.
    if (m_simt.policy == SimtPolicy::while_while && want[last]) return last;
    for (uint32_t i = 1; i <= kClasses; ++i)
        if (want[(last + i) % kClasses]) return (last + i) % kClasses;
    return last;
}

void SimtUnit::step(uint32_t w, Cycle t) {
    // The steps the rays' walks took in the last warp step have run: their dependants are ready.
    if (m_walks)
        for (uint32_t l = first_lane(w); l < first_lane(w) + m_simt.lanes; ++l)
            if (m_lanes[l].has_ray) m_lanes[l].walk.release();
    if (retire_and_refill(w, t)) return fetch_rays(w, t);
    if (m_treelet_mode) {
        park_leavers(w, t);
        // Every ray left the warp's treelet (or finished): the warp forms again from a queue.
        if (!warp_has_ray(w) && retire_and_refill(w, t)) return fetch_rays(w, t);
    }
    const uint32_t cls = choose_class(w);
    if (cls == kClasses) return;  // every lane finished and no ray is to be had now: the warp idles
    Warp& warp = m_warps[w];
    warp.last_class = cls;
    // The lanes whose next step runs the warp's kind step (costed and run with the one
    // arithmetic as their fetches issue); their fetches are coalesced per line.
    for (uint32_t l = first_lane(w); l < first_lane(w) + m_simt.lanes; ++l) {
        Lane& lane = m_lanes[l];
        lane.stepping = lane.has_ray && lane_class(l) == cls;
        if (!lane.stepping) continue;
        account_until(m_account, lane.accounted, CycleUse::issue, t);
        if (m_walks) {
            take_walk_step(l, l, cls, t);
            continue;
        }
        lane.spare = lane.ray.stepper->stack_size();
        if (m_prefetcher.on() && !m_treelet_mode) note_treelet(l, t);
        step_ray(l, l, m_treelet_mode ? warp.treelet : lane.treelet);
    }
    if (m_simt.cooperative) lend_idle_lanes(w, cls, t);
    AccessInfo slowest;
    const Cycle ready = issue_reads(t, &slowest);
    for (uint32_t l = first_lane(w); l < first_lane(w) + m_simt.lanes; ++l)
        if (m_lanes[l].stepping) account_read_until(m_account, m_lanes[l].accounted, ready, slowest);
    account_idle(w, ready);
    count_warp_step(w, t);
    warp.phase = Phase::ops;
    m_events.schedule(w, ready);
}

void SimtUnit::step_ray(uint32_t owner, uint32_t into, uint32_t treelet) {
    Lane& o = m_lanes[owner];
    const int before = o.ray.stepper->stack_size();
    take_step_reading(*o.ray.stepper, o.ray.stack, m_costs, m_lanes[into].demand, [&](const Fetch& f) {
        if (m_prefetcher.on() && treelet != kNoTreelet) m_prefetcher.learn(treelet, f);
        m_coalescer.add(f.addr, f.bytes, f.kind);
    });
    m_stack_prefetch.after_step(owner, *o.ray.stepper, before);
}

void SimtUnit::take_walk_step(uint32_t owner, uint32_t into, uint32_t cls, Cycle t) {
    Lane& o = m_lanes[owner];
    Fetch reads[StepPlan::kMaxFetches];
    Fetch prefetch[StackPrefetcher::kMaxEntries];
    uint32_t n = 0, np = 0;
    const uint32_t locality = o.walk.take(
        cls, m_lanes[into].demand, [&](const Fetch& f) { reads[n++] = f; },
        [&](const Fetch& f) {
            if (np < StackPrefetcher::kMaxEntries) prefetch[np++] = f;
        });
    // Prefetching without queues: the step's node entered another treelet of this ray's.
    if (m_prefetcher.on() && locality != kNoLocality) {
        const uint32_t treelet = m_treelets->treelet_of(locality);
        if (treelet != o.treelet) o.treelet = treelet, m_prefetcher.enter(owner, treelet, t);
    }
    for (uint32_t i = 0; i < n; ++i) {
        if (m_prefetcher.on() && o.treelet != kNoTreelet) m_prefetcher.learn(o.treelet, reads[i]);
        m_coalescer.add(reads[i].addr, reads[i].bytes, reads[i].kind);
    }
    if (np) m_stack_prefetch.arm(owner, prefetch, np);
}

void SimtUnit::lend_idle_lanes(uint32_t w, uint32_t cls, Cycle t) {
    const uint32_t begin = first_lane(w), end = begin + m_simt.lanes;
    // Idle lanes wait for the warp (warp refill) or for rays (lane refill) until now.
    const CycleUse waited = m_simt.refill == SimtRefill::warp ? CycleUse::idle_lane : CycleUse::starved;
    bool helped = false;
    for (uint32_t h = begin; h < end; ++h) {
        Lane& helper = m_lanes[h];
        if (helper.has_ray) continue;
        // Recorded walks: the ray with the most ready steps of the warp's kind. Otherwise the
        // stepping ray with the most stack entries not yet handed over whose next step runs the
        // warp's kind (and, with treelet queues, stays in the warp's treelet).
        const uint32_t best =
            m_walks
                ? pick_helped_lane(
                      begin, m_simt.lanes, [&](uint32_t l) { return m_lanes[l].has_ray ? m_lanes[l].walk.ready(cls) : 0; },
                      [](uint32_t) { return true; })
                : pick_helped_lane(
                      begin, m_simt.lanes,
                      [&](uint32_t l) { return m_lanes[l].stepping && m_lanes[l].helps == kNoLane ? m_lanes[l].spare : 0; },
                      [&](uint32_t l) {
                          const StepPlan& plan = m_lanes[l].ray.stepper->plan();
                          if (plan.done || step_class(plan) != cls) return false;
                          return !m_treelet_mode || plan.locality == kNoLocality ||
                                 m_treelets->treelet_of(plan.locality) == m_warps[w].treelet;
                      });
        if (best == end) break;  // no ray has independent work of this kind left
        Lane& owner = m_lanes[best];
        account_until(m_account, helper.accounted, waited, t);
        helper.helps = best;
        helper.stepping = true;
        if (m_walks) {
            take_walk_step(best, h, cls, t);
        } else {
            --owner.spare;
            step_ray(best, h, m_treelet_mode ? m_warps[w].treelet : owner.treelet);
        }
        ++m_helper_steps;
        helped = true;
    }
    if (helped) ++m_helped_warp_steps;
}

void SimtUnit::run_ops(uint32_t w, Cycle t) {
    // Each kind's issues of all stepping lanes go to its pipeline, kinds in the order the lanes'
    // demands list them; then each lane's stack traffic. The warp waits for the slowest.
    std::array<uint32_t, kOpKindCount> issues{}, tests{};
    std::array<bool, kOpKindCount> seen{};
    std::array<OpKind, kOpKindCount> order{};
    uint32_t kinds = 0;
    const uint32_t begin = first_lane(w), end = begin + m_simt.lanes;
    for (uint32_t l = begin; l < end; ++l) {
        if (!m_lanes[l].stepping) continue;
        account_until(m_account, m_lanes[l].accounted, CycleUse::issue, t);
        if (m_stack_prefetch.on()) m_stack_prefetch.issue(ray_lane(l), *mem[0], t);
        const StepDemand& d = m_lanes[l].demand;
        for (int i = 0; i < d.issue_count; ++i) {
            const size_t k = size_t(d.issues[i].kind);
            if (!seen[k]) seen[k] = true, order[kinds++] = d.issues[i].kind;
            issues[k] += d.issues[i].issues;
            tests[k] += d.issues[i].tests;
        }
    }
    Cycle ready = t;
    for (uint32_t i = 0; i < kinds; ++i) {
        const size_t k = size_t(order[i]);
        ready = pipes[k]->issue(ready, issues[k], tests[k]);
        for (uint32_t l = begin; l < end; ++l)
            if (m_lanes[l].stepping) account_until(m_account, m_lanes[l].accounted, pipe_use(order[i]), ready);
    }
    const Cycle ops_done = ready;
    for (uint32_t l = begin; l < end; ++l) {
        if (!m_lanes[l].stepping) continue;
        // Spill slots belong to the lane, or with treelets to the ray (it moves between units); a
        // helper's are its ray's.
        const uint32_t r = ray_lane(l);
        const uint64_t owner = m_treelet_mode ? m_lanes[r].ray.ray_id : uint64_t(m_index) * m_lanes.size() + r;
        ready = std::max(ready, issue_stack_traffic(*mem[0], m_map, m_lanes[l].demand, owner, m_costs.stack_entry_bytes, t,
                                                    ops_done, &m_tally.spill_writes, &m_tally.spill_reads, [] {}));
    }
    for (uint32_t l = begin; l < end; ++l)
        if (m_lanes[l].stepping) account_until(m_account, m_lanes[l].accounted, CycleUse::stack, ready);
    account_idle(w, ready);
    m_warps[w].phase = Phase::step;
    m_events.schedule(w, ready);
}

Cycle SimtUnit::issue_reads(Cycle t, AccessInfo* slowest) {
    StepReads reads(*mem[0], t);
    m_coalescer.issue([&](uint64_t addr, uint32_t bytes, DataKind kind) { reads.read(addr, bytes, kind); });
    *slowest = reads.slowest();
    return reads.ready();
}

void SimtUnit::account_idle(uint32_t w, Cycle until) {
    const bool waiting = m_simt.refill == SimtRefill::warp && warp_has_ray(w);
    for (uint32_t l = first_lane(w); l < first_lane(w) + m_simt.lanes; ++l) {
        Lane& lane = m_lanes[l];
        if (!lane.stepping && (lane.has_ray || waiting)) account_until(m_account, lane.accounted, CycleUse::idle_lane, until);
    }
}

void SimtUnit::count_warp_step(uint32_t w, Cycle t) {
    uint32_t active = 0;
    for (uint32_t l = first_lane(w); l < first_lane(w) + m_simt.lanes; ++l) {
        const Lane& lane = m_lanes[l];
        if (!lane.has_ray && lane.helps == kNoLane) continue;
        const RayKind kind = m_lanes[ray_lane(l)].ray.kind;  // a helper counts in its ray's kind
        ++m_kind_present[size_t(kind)];
        if (lane.stepping) ++active, ++m_kind_active[size_t(kind)];
    }
    ++m_warp_steps;
    m_lane_steps += active;
    ++m_active_histogram[active];
    m_slot_use.add(t, m_simt.lanes);
    m_active_use.add(t, active);
}

nlohmann::json SimtUnit::efficiency_by_kind() const {
    nlohmann::json out = nlohmann::json::object();
    for (int k = 0; k < kRayKindCount; ++k)
        if (m_kind_present[size_t(k)])
            out[ray_kind_name(RayKind(k))] = double(m_kind_active[size_t(k)]) / double(m_kind_present[size_t(k)]);
    return out;
}

nlohmann::json SimtUnit::efficiency_over_time() const {
    // Active lanes / lane slots per point, the points as UsageSeries::to_json groups them.
    const nlohmann::json slots = m_slot_use.to_json(1.0), active = m_active_use.to_json(1.0);
    nlohmann::json out = nlohmann::json::array();
    for (size_t i = 0; i < slots.size() && i < active.size(); ++i) {
        const double s = slots[i]["value"].get<double>();
        out.push_back({{"cycle", slots[i]["cycle"]}, {"value", s > 0 ? active[i]["value"].get<double>() / s : 0.0}});
    }
    return out;
}

void SimtUnit::finish_lane(uint32_t l, Cycle t) {
    Lane& lane = m_lanes[l];
    account_until(m_account, lane.accounted, CycleUse::issue, t);  // done, waiting for its warp's step
    const Stepper& s = *lane.ray.stepper;
    const RayResult r{lane.ray.ray_id, s.hit(), s.work(), lane.ray.start, t, m_index, l, s.mode()};
    m_tally.finish_ray(*mem[0], m_map, r);
    sink->ray_done(r);
    if (m_treelet_mode) ray_buffer->finished(t);
    else rays->ray_finished(t);
    lane.has_ray = false;
    m_tally.busy.leave(t);
}

CycleAccount SimtUnit::cycle_account(Cycle total_cycles) const {
    return with_tail(m_account, m_lanes, total_cycles);
}

const StatTable<SimtUnit>& SimtUnit::kind_stats() {
    static const StatTable<SimtUnit> table{
        "model.units.<unit> (simt)",
        {
            {{"warp_steps", "steps", "warp steps (one operation kind for the warp, or the new rays' record fetch)", /*timed=*/true},
             [](const SimtUnit& u) { return u.m_warp_steps; }},
            {{"ray_fetch_steps", "steps", "warp steps that fetched new rays' records", /*timed=*/true},
             [](const SimtUnit& u) { return u.m_fetch_steps; }},
            {{"active_lane_histogram", "steps", "warp steps by active lanes, index 0 .. `traversal.simt.lanes`", /*timed=*/true},
             [](const SimtUnit& u) { return u.m_active_histogram; }},
            {{"simd_efficiency_by_kind", "fraction", "`{ray kind: lanes of that kind that stepped / lanes holding a ray of that kind}` over warp steps (empty lanes are in no kind)", /*timed=*/true},
             [](const SimtUnit& u) { return u.efficiency_by_kind(); }},
            {{"simd_efficiency_over_time", "fraction", "`[{cycle, value}]`, active lanes / lane slots of the warp steps issued in each interval (at most 256 points)", /*timed=*/true},
             [](const SimtUnit& u) { return u.efficiency_over_time(); }},
            {{"helper_steps", "steps", "cooperative lanes only (`traversal.simt.cooperative`, CoopRT): ray steps a lane without a ray of its own ran for another lane's ray (each also counted in `active_lanes`)", /*timed=*/true},
             [](const SimtUnit& u) { return u.m_helper_steps; }},
            {{"helped_warp_steps", "steps", "cooperative lanes only: warp steps in which at least one helper stepped", /*timed=*/true},
             [](const SimtUnit& u) { return u.m_helped_warp_steps; }},
            {{"lane_requests", "requests", "reads the stepping lanes asked for (a MIMD unit's requests for the same steps)", /*timed=*/true},
             [](const SimtUnit& u) { return u.m_coalescer.lane_requests(); }},
            {{"coalesced_requests", "requests", "read requests after coalescing a warp step's reads per L1 line", /*timed=*/true},
             [](const SimtUnit& u) { return u.m_coalescer.requests(); }},
        }};
    return table;
}

nlohmann::json SimtUnit::stats_json(Cycle total_cycles) const {
    nlohmann::json j;
    const uint64_t slots = m_warp_steps * m_simt.lanes;
    StatsWriter w(unit_stats_of("simt"), j);
    m_tally.write(w, m_sync, cycle_account(total_cycles), total_cycles);
    w.set("lane_slots", slots)
        .set("active_lanes", m_lane_steps)
        .set("simd_efficiency", slots ? double(m_lane_steps) / double(slots) : 0.0);
    if (m_treelet_mode) w.set("rays_taken", m_takes).set("rays_parked", m_parks).set("idle_polls", m_idle_polls);
    if (m_prefetcher.on()) w.set("prefetch", m_prefetcher.stats_json());
    if (m_stack_prefetch.on()) w.set("stack_prefetch", m_stack_prefetch.stats_json());
    kind_stats().write(*this, j);
    w.done();
    return j;
}

namespace {

UnitKind simt_kind() {
    UnitKind k;
    k.name = "simt";
    k.summary = "warps of traversal.simt.lanes ray contexts stepping in lock-step, one operation kind per warp step "
                "(Aila & Laine 2009; Vulkan-Sim's RT unit)";
    k.make_unit = [](const char* name, const UnitSetup& setup, uint32_t index) -> std::unique_ptr<TraversalUnit> {
        return std::make_unique<SimtUnit>(name, setup, index);
    };
    k.section<SimtConfig>();
    k.stats = &SimtUnit::kind_stats().block();
    k.group_size = [](const TraversalConfig& t) { return t.kinds.of<SimtConfig>("simt").lanes; };
    k.group_name = "warp";
    k.needs.lock_step = true;
    // Under treelet scheduling each warp takes one treelet queue's rays (Aila & Karras 2010's
    // queues run by warps, as Chou et al. 2023 evaluate on Vulkan-Sim's RT unit).
    k.treelet_consumers = [](const TraversalConfig& t) { return t.groups(); };
    // Narrower warps diverge less; the analytic level has no warps, so only a re-run measures it.
    k.knobs = {{"traversal.simt.lanes", /*halve=*/true, "divergence", /*estimated=*/false}};
    k.estimate_as = "mimd";
    k.group_profile = simt_group_profile;
    return k;
}

const StatBlock& simt_stats_block() { return SimtUnit::kind_stats().block(); }

}  // namespace

RTSIM_REGISTER_UNIT_KIND(simt_kind())
RTSIM_REGISTER_STAT_BLOCK(simt_stats_block)

}  // namespace rtsim
