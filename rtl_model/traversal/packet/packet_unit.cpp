#include "rtl_model/traversal/packet/packet_unit.h"
#include "rtl_model/traversal/packet/packet_profile.h"

#include <algorithm>
#include <string>

#include "traces/common/error.h"

namespace rtsim {

namespace {

/// The machine's step costs with a packet's stack entry.
StepCosts packet_costs(StepCosts costs, uint32_t lanes) {
    costs.stack_entry_bytes = packet_stack_entry_bytes(costs.stack_entry_bytes, lanes);
    return costs;
}

/// The scheduler's slots: one per packet, and with split rays walking on their lanes, one per lane.
uint32_t slots(const TraversalConfig& t) {
    const PacketConfig& p = t.kind_config<PacketConfig>();
    return p.split_walks == SplitWalks::lanes ? t.groups() * (1 + p.lanes) : t.groups();
}

}  // namespace

PacketUnit::PacketUnit(sc_core::sc_module_name name, const UnitSetup& setup, uint32_t index)
    : ScheduledUnit(name, setup, index, slots(setup.config),
                    packet_costs(setup.costs, setup.config.kind_config<PacketConfig>().lanes)),
      m_packet(setup.config.kind_config<PacketConfig>()),
      m_lane_costs(setup.costs),
      m_packets(setup.config.groups()),
      m_coalescer(setup.context.line_bytes),
      m_active_histogram(m_packet.lanes + 1, 0),
      m_results(m_packet.lanes),
      m_rays(m_packet.lanes),
      m_modes(m_packet.lanes) {
    // The run's resolution step refused structures without a packet kernel (capabilities.h).
    for (Packet& p : m_packets) {
        p.stepper = m_steppers.accel().make_packet_stepper(m_steppers.options());
        require(p.stepper != nullptr, "model: structure '" + m_steppers.accel().kind() + "' has no packet kernel");
        p.stepper->set_split_below(float(m_packet.split_below));
        p.stepper->set_split_walks(m_packet.split_walks);
        p.ids.resize(m_packet.lanes);
        if (m_packet.split_walks == SplitWalks::lanes) p.lanes.resize(m_packet.lanes);
    }
    attach_stack_prefetch(uint32_t(m_packets.size()));  // one stream per packet: its shared stack
    SC_THREAD(run);
}

void PacketUnit::run() {
    Cycle now = 0;
    fill_idle_packets(0);
    for (;;) {
        if (m_events.empty()) {
            if (!await_next_release(rays, m_release)) break;  // no packet in flight
            fill_idle_packets(now);
            continue;
        }
        const Cycle ready = m_events.top_time();
        const uint32_t slot = m_events.begin_pop();
        // The scheduler takes one phase of one packet (or one walking lane) per issue_cycles.
        const Cycle t = std::max(ready, m_sched_free);
        m_sched_free = t + m_config.issue_cycles;
        now = t;
        if (slot < m_packets.size()) {
            if (m_ctx.sync_private_steps || m_packets[slot].phase != Phase::ops) m_sync(t);
            advance(slot, t);
        } else {
            const uint32_t p = (slot - uint32_t(m_packets.size())) / m_packet.lanes;
            const uint32_t i = (slot - uint32_t(m_packets.size())) % m_packet.lanes;
            if (m_ctx.sync_private_steps || m_packets[p].lanes[i].phase != Phase::ops) m_sync(t);
            advance_lane(p, i, t);
        }
        m_events.finish_pop();
        if (rays->releases() != m_release) {  // a frame or held rays were released: fill every idle packet
            if (!m_ctx.sync_private_steps) m_sync(t);
            m_release = rays->releases();
            fill_idle_packets(t);
        }
    }
}

void PacketUnit::fill_idle_packets(Cycle t) {
    for (uint32_t p = 0; p < m_packets.size(); ++p)
        if (!m_packets[p].active && !start_packet(p, t)) break;
}

void PacketUnit::account(uint32_t p, CycleUse use, Cycle until) {
    Packet& pk = m_packets[p];
    if (until <= pk.accounted) return;
    const Cycle dt = until - pk.accounted;
    m_account.add(use, dt * pk.weight);
    m_account.add(CycleUse::idle_lane, dt * (m_packet.lanes - pk.weight));
    pk.accounted = until;
}

void PacketUnit::account_read(uint32_t p, Cycle ready, const AccessInfo& info) {
    Packet& pk = m_packets[p];
    if (ready <= pk.accounted) return;
    CycleAccount read;
    account_memory(read, pk.accounted, ready, info);
    for (CycleUse use : {CycleUse::l1_mshr_full, CycleUse::l2_mshr_full, CycleUse::l1_hit, CycleUse::l2, CycleUse::dram})
        m_account.add(use, read[use] * pk.weight);
    m_account.add(CycleUse::idle_lane, (ready - pk.accounted) * (m_packet.lanes - pk.weight));
    pk.accounted = ready;
}

bool PacketUnit::start_packet(uint32_t p, Cycle t) {
    Packet& pk = m_packets[p];
    uint32_t n = 0;
    Cycle start = t;
    RayJob job;
    m_coalescer.clear();
    while (n < m_packet.lanes && rays->next_ray(m_index, &job)) {
        start = std::max(start, job.not_before);  // a frame's rays start when the previous frame is done
        m_rays[n] = job.ray;
        m_modes[n] = job.any_hit ? TraversalMode::any_hit : TraversalMode::closest_hit;
        pk.ids[n] = job.id;
        if (!ray_is_valid(job.ray)) ++m_tally.rejected;
        m_coalescer.add(m_map.ray(job.id), sizeof(RayRecord), DataKind::ray);
        ++n;
    }
    if (n == 0) return false;
    pk.stepper->begin_packet(m_rays.data(), m_modes.data(), n);
    m_stack_prefetch.begin(p);
    pk.start = start;
    pk.stack = StackSplit{};
    pk.weight = m_packet.lanes;
    account(p, CycleUse::starved, start);  // idle until now, while rays were still to come
    pk.active = true;
    m_tally.busy.enter(start);
    ++m_packets_traced;
    // The rays' records are read (coalesced per line) before traversal starts.
    pk.weight = n;
    const Cycle fetch = start + m_ctx.dispatch_latency;
    account(p, CycleUse::dispatch, fetch);
    StepReads reads(*mem[0], fetch);
    m_coalescer.issue([&](uint64_t addr, uint32_t bytes, DataKind kind) { reads.read(addr, bytes, kind); });
    account_read(p, reads.ready(), reads.slowest());
    pk.phase = Phase::step;
    m_events.schedule(p, reads.ready());
    return true;
}

void PacketUnit::advance(uint32_t p, Cycle t) {
    ++m_tally.steps;
    Packet& pk = m_packets[p];
    account(p, CycleUse::issue, t);  // ready since its event, waiting for the scheduler
    if (pk.phase == Phase::ops) return run_ops(p, t);
    if (pk.stepper->plan().done) {
        if (pk.stepper->split_lanes() && !pk.walking) return launch_lanes(p, t);
        return finish_packet(p, t);
    }
    step(p, t);
}

void PacketUnit::launch_lanes(uint32_t p, Cycle t) {
    // The packet split: each ray with steps left walks on its own lane from now on; the packet's
    // own context waits for the last of them.
    Packet& pk = m_packets[p];
    account(p, CycleUse::issue, t);
    pk.walking = pk.stepper->split_lanes();
    for_each_lane(pk.walking, [&](uint32_t i) {
        Lane& l = pk.lanes[i];
        const uint32_t entries = uint32_t(pk.stepper->lane_walker(i).stack_size());
        l.stack.local = std::min(entries, m_lane_costs.stack_entries);
        l.stack.spilled = entries - l.stack.local;
        l.phase = Phase::step;
        l.accounted = t;
        m_events.schedule(lane_slot(p, i), t);
    });
    pk.weight = 0;  // the lanes account for themselves until the packet ends
}

void PacketUnit::advance_lane(uint32_t p, uint32_t i, Cycle t) {
    ++m_tally.steps;
    Packet& pk = m_packets[p];
    Lane& l = pk.lanes[i];
    Stepper& walker = pk.stepper->lane_walker(i);
    account_until(m_account, l.accounted, CycleUse::issue, t);
    if (l.phase == Phase::ops) {
        // As run_ops, for one ray: its tests, then its spilled entries read back.
        Cycle ready = t;
        const StepDemand& d = l.demand;
        for (int k = 0; k < d.issue_count; ++k) {
            ready = pipes[size_t(d.issues[k].kind)]->issue(ready, d.issues[k].issues, d.issues[k].tests);
            account_until(m_account, l.accounted, pipe_use(d.issues[k].kind), ready);
        }
        const uint64_t owner = uint64_t(m_index) * m_config.contexts() + p * m_packet.lanes + i;
        ready = issue_stack_traffic(*mem[0], m_map, d, owner, m_lane_costs.stack_entry_bytes, t, ready,
                                    &m_tally.spill_writes, &m_tally.spill_reads, [&] {
                                        if (!m_ctx.sync_private_steps) m_sync(t);
                                    });
        account_until(m_account, l.accounted, CycleUse::stack, ready);
        l.phase = Phase::step;
        m_events.schedule(lane_slot(p, i), ready);
        return;
    }
    if (walker.plan().done) return lane_done(p, i, t);
    // As step, for one ray: its one fetch, then its operations once the data is in.
    ++m_packet_steps;
    ++m_active_rays;
    ++m_active_histogram[1];
    StepReads reads(*mem[0], t);
    take_step_reading(walker, l.stack, m_lane_costs, l.demand, [&](const Fetch& f) {
        m_node_fetches += f.kind == DataKind::node || f.kind == DataKind::cell;
        reads.read(f);
    });
    account_read_until(m_account, l.accounted, reads.ready(), reads.slowest());
    l.phase = Phase::ops;
    m_events.schedule(lane_slot(p, i), reads.ready());
}

void PacketUnit::lane_done(uint32_t p, uint32_t i, Cycle t) {
    Packet& pk = m_packets[p];
    pk.walking &= ~lane_bit(i);
    if (pk.walking) return;
    // The last lane is done: every lane not walking was idle since it stopped (or the split).
    for (uint32_t k = 0; k < m_packet.lanes; ++k) {
        const Cycle since = pk.stepper->split_lanes() & lane_bit(k) ? pk.lanes[k].accounted : pk.accounted;
        if (t > since) m_account.add(CycleUse::idle_lane, t - since);
    }
    pk.accounted = t;
    finish_packet(p, t);
}

void PacketUnit::step(uint32_t p, Cycle t) {
    Packet& pk = m_packets[p];
    // The packet's step is costed (and run, each ray with the one arithmetic) as its one fetch
    // issues; its operations phase issues the active rays' tests once the data has arrived.
    const uint32_t active = pk.stepper->active();
    pk.weight = active;
    ++m_packet_steps;
    m_active_rays += active;
    ++m_active_histogram[active];
    StepDemand& d = pk.demand;
    StepReads reads(*mem[0], t);
    const int stack_before = pk.stepper->stack_size();
    take_step_reading(*pk.stepper, pk.stack, m_costs, d, [&](const Fetch& f) {
        m_node_fetches += f.kind == DataKind::node || f.kind == DataKind::cell;
        reads.read(f);
    });
    m_stack_prefetch.after_step(p, *pk.stepper, stack_before);  // the packet's shared stack (TTP)
    account_read(p, reads.ready(), reads.slowest());
    pk.phase = Phase::ops;
    m_events.schedule(p, reads.ready());
}

void PacketUnit::run_ops(uint32_t p, Cycle t) {
    // The active rays' tests run on their pipelines in order (the plan's, then the alpha tests
    // their hits called for), then spilled stack entries are read back.
    Packet& pk = m_packets[p];
    const StepDemand& d = pk.demand;
    if (m_stack_prefetch.on()) m_stack_prefetch.issue(p, *mem[0], t);
    Cycle ready = t;
    for (int i = 0; i < d.issue_count; ++i) {
        ready = pipes[size_t(d.issues[i].kind)]->issue(ready, d.issues[i].issues, d.issues[i].tests);
        account(p, pipe_use(d.issues[i].kind), ready);
    }
    // Spill slots belong to the packet context, reused packet after packet.
    const uint64_t owner = uint64_t(m_index) * m_packets.size() + p;
    ready = issue_stack_traffic(*mem[0], m_map, d, owner, m_costs.stack_entry_bytes, t, ready, &m_tally.spill_writes,
                                &m_tally.spill_reads, [&] {
                                    if (!m_ctx.sync_private_steps) m_sync(t);
                                });
    account(p, CycleUse::stack, ready);
    pk.phase = Phase::step;
    m_events.schedule(p, ready);
}

void PacketUnit::finish_packet(uint32_t p, Cycle t) {
    Packet& pk = m_packets[p];
    const PacketStepper& s = *pk.stepper;
    const uint32_t n = s.size();
    m_splits += s.counts().splits;
    m_split_steps += s.counts().split_steps;
    for (uint32_t i = 0; i < n; ++i) {
        m_results[i] = RayResult{pk.ids[i], s.lane_hit(i), s.lane_work(i), pk.start, t, m_index, p * m_packet.lanes + i,
                                 s.lane_mode(i)};
        m_tally.finish_ray(*mem[0], m_map, m_results[i]);
        m_rays[i] = s.lane_ray(i);
        m_modes[i] = s.lane_mode(i);
    }
    sink->packet_done(m_results.data(), m_rays.data(), m_modes.data(), n);
    for (uint32_t i = 0; i < n; ++i) rays->ray_finished(t);
    pk.active = false;
    m_tally.busy.leave(t);
    start_packet(p, t);
}

CycleAccount PacketUnit::cycle_account(Cycle total_cycles) const {
    return with_tail(m_account, m_packets, total_cycles, m_packet.lanes);
}

const StatTable<PacketUnit>& PacketUnit::kind_stats() {
    using json = nlohmann::json;
    static const StatTable<PacketUnit> table{
        "model.units.<unit> (packet)",
        {
            {{"packets", "packets", "packets traced (each up to `traversal.packet.lanes` rays taken from dispatch together)", /*timed=*/true},
             [](const PacketUnit& u) { return u.m_packets_traced; }},
            {{"packet_steps", "steps", "packet steps (one node or leaf fetch serving the packet's active rays)", /*timed=*/true},
             [](const PacketUnit& u) { return u.m_packet_steps; }},
            {{"packet_node_fetches", "fetches", "node (or grid cell) fetches, one per packet node step", /*timed=*/true},
             [](const PacketUnit& u) { return u.m_node_fetches; }},
            {{"node_fetches_per_packet", "fetches", "`packet_node_fetches / packets`", /*timed=*/true},
             [](const PacketUnit& u) {
                 return json(u.m_packets_traced ? double(u.m_node_fetches) / double(u.m_packets_traced) : 0.0);
             }},
            {{"packet_occupancy", "rays", "active rays per packet step (`active_lanes / packet_steps`; Wald et al. 2001's packets keep it near `traversal.packet.lanes` on coherent rays)", /*timed=*/true},
             [](const PacketUnit& u) {
                 return json(u.m_packet_steps ? double(u.m_active_rays) / double(u.m_packet_steps) : 0.0);
             }},
            {{"packet_active_histogram", "steps", "packet steps by active rays, index 0 .. `traversal.packet.lanes`", /*timed=*/true},
             [](const PacketUnit& u) { return u.m_active_histogram; }},
            {{"packet_splits", "packets", "packets that split into single rays (`traversal.packet.split_below`, Benthin et al. 2012's hybrid)", /*timed=*/true},
             [](const PacketUnit& u) { return u.m_splits; }},
            {{"packet_split_steps", "steps", "of `packet_steps`, the single-ray steps after a split (one ray active each)", /*timed=*/true},
             [](const PacketUnit& u) { return u.m_split_steps; }},
        }};
    return table;
}

nlohmann::json PacketUnit::stats_json(Cycle total_cycles) const {
    nlohmann::json j;
    StatsWriter w(unit_stats_of("packet"), j);
    m_tally.write(w, m_sync, cycle_account(total_cycles), total_cycles);
    const uint64_t slots = m_packet_steps * m_packet.lanes;
    w.set("lane_slots", slots)
        .set("active_lanes", m_active_rays)
        .set("simd_efficiency", slots ? double(m_active_rays) / double(slots) : 0.0);
    if (m_stack_prefetch.on()) w.set("stack_prefetch", m_stack_prefetch.stats_json());
    kind_stats().write(*this, j);
    w.done();
    return j;
}

namespace {

UnitKind packet_kind() {
    UnitKind k;
    k.name = "packet";
    k.summary = "packets of traversal.packet.lanes rays sharing one traversal stack and one node fetch per step "
                "(Wald et al. 2001), splitting into single rays below traversal.packet.split_below (Benthin et al. 2012)";
    k.make_unit = [](const char* name, const UnitSetup& setup, uint32_t index) -> std::unique_ptr<TraversalUnit> {
        return std::make_unique<PacketUnit>(name, setup, index);
    };
    k.section<PacketConfig>();
    k.stats = &PacketUnit::kind_stats().block();
    k.group_size = [](const TraversalConfig& t) { return t.kinds.of<PacketConfig>("packet").lanes; };
    k.group_name = "packet";
    k.needs.packet_kernel = true;
    k.needs.lock_step = true;
    k.needs.per_ray_stack = false;
    k.needs.treelet_queues = false;
    k.needs.treelet_prefetch = false;
    k.knobs = {{"traversal.packet.lanes", /*halve=*/true, "divergence", /*estimated=*/false}};
    k.estimate_as = "mimd";
    k.group_profile = packet_group_profile;
    k.packet_reference = [](const TraversalConfig& t) {
        const PacketConfig& p = t.kinds.of<PacketConfig>("packet");
        return PacketReference{p.lanes, float(p.split_below)};
    };
    return k;
}

const StatBlock& packet_stats_block() { return PacketUnit::kind_stats().block(); }

}  // namespace

RTSIM_REGISTER_UNIT_KIND(packet_kind())
RTSIM_REGISTER_STAT_BLOCK(packet_stats_block)

}  // namespace rtsim
