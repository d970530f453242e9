#include "rtl_model/ray_buffer/ray_buffer.h"

#include <algorithm>
#include <string>

#include "traces/common/error.h"

namespace rtsim {

RayBuffer::RayBuffer(sc_core::sc_module_name name, const TreeletConfig& config, const TreeletMap& treelets,
                     const MemoryMap& map, StepperPool& steppers, uint32_t units, uint32_t ray_contexts,
                     uint32_t consumers, uint32_t state_bytes, Cycle lookahead)
    : sc_core::sc_module(name),
      m_config(config),
      m_treelets(treelets),
      m_map(map),
      m_steppers(steppers),
      m_state_bytes(state_bytes),
      m_capacity(std::max<uint64_t>(1, uint64_t(config.buffer_kib) * 1024 / m_state_bytes)),
      m_max_in_flight(config.max_rays_in_flight ? config.max_rays_in_flight
                                                : m_capacity + uint64_t(units) * ray_contexts),
      m_queues(treelets.treelets()),
      m_consumer_treelet(consumers, -1),
      m_admit_slots(config.admit_outstanding, 0),  // (the config allows at most MinTree::kMaxSlots)
      m_lookahead(lookahead),
      m_sram(16ull * config.bytes_per_cycle, 16),
      m_by_size(config.policy == TreeletPolicy::largest ? treelets.treelets() : 1) {
    SC_THREAD(admission);
    require(config.policy != TreeletPolicy::largest || treelets.treelets() <= SizeTree::kMaxSlots,
            "ray buffer: " + std::to_string(treelets.treelets()) + " treelets, at most " +
                std::to_string(SizeTree::kMaxSlots) + " (raise treelets.treelet_kib)");
}

Cycle RayBuffer::sram(Cycle time) {
    // One ray state moved through the SRAM port: bandwidth, then latency.
    Cycle start = m_sram.reserve(time, m_state_bytes);
    return start + m_config.latency + (m_state_bytes + m_config.bytes_per_cycle - 1) / m_config.bytes_per_cycle;
}

void RayBuffer::push(uint32_t treelet, RayState&& ray, Cycle ready, Cycle time) {
    Waiting w{std::move(ray), ready, false, 0};
    if (m_occupancy < m_capacity) {
        ++m_occupancy;
        m_max_occupancy = std::max(m_max_occupancy, m_occupancy);
        w.ready = std::max(ready, sram(time));
    } else {
        // SRAM full: the state overflows to memory (posted write).
        w.overflowed = true;
        if (!m_free_slots.empty()) {
            w.slot = m_free_slots.back();
            m_free_slots.pop_back();
        } else {
            w.slot = m_next_slot++;
        }
        mem->access({m_map.ray_buffer(w.slot, m_state_bytes), m_state_bytes, true, DataKind::ray_buffer, time});
        ++m_overflows;
    }
    unindex(treelet);
    m_queues[treelet].push_back(std::move(w));
    index(treelet);
}

bool RayBuffer::has_room() const {
    // By default (no explicit limit) admission also waits for SRAM room, so it never overflows.
    // It leaves one entry free: a unit parks a ray and takes the next in one step, so the SRAM
    // briefly holds one more than before (a full SRAM would overflow that ray to memory).
    const bool may_overflow = m_config.max_rays_in_flight != 0;
    const uint64_t reserve = m_capacity > 1 ? 1 : 0;
    return m_in_machine < m_max_in_flight && (may_overflow || m_occupancy + reserve < m_capacity);
}

void RayBuffer::admit_until(Cycle time, Cycle horizon) {
    // New rays enter the queue of their first step's treelet (the root treelet for a tree)
    // while the machine holds fewer than the limit.
    RayJob job;
    while (!m_dispatch_empty && !m_dispatch_held && has_room() && next_admit_issue(time) <= horizon) {
        if (!rays->next_ray(RaySourceIf::kAnyUnit, &job)) {
            // At a frame barrier dispatch holds the next frame's rays until this one's are done.
            if (rays->exhausted() || rays->released() == nullptr) {
                m_dispatch_empty = true;
            } else {
                m_dispatch_held = true;
                m_held_at = rays->releases();
            }
            break;
        }
        RayState s;
        s.stepper = m_steppers.acquire();
        s.stepper->begin(job.ray, job.any_hit ? TraversalMode::any_hit : TraversalMode::closest_hit);
        s.ray_id = job.id;
        s.kind = job.kind;
        const uint32_t treelet = m_treelets.first_treelet(s.stepper->plan().locality);
        const Cycle issue = std::max(next_admit_issue(time), job.not_before);  // a frame starts at its barrier
        s.start = issue;
        const Cycle fetched = fetch_ray_record(job.id, issue);
        push(treelet, std::move(s), fetched, issue);
        ++m_admitted;
        ++m_in_machine;
    }
}

void RayBuffer::admission() {
    // The engine streams: it issues a read only when the read's cycle is at most a lookahead
    // past SystemC time, so the L2 and DRAM see its reads in time order with the units' own.
    // (Until 2026-11-24 the first unit to ask admitted every ray at once, stamping thousands of
    // reads up to 10^5 cycles into the future: at the detailed level those took the L2's MSHRs
    // and the DRAM's slots ahead of the units' requests. docs/treelets.md, "Admission".)
    for (;;) {
        const Cycle now = sc_core::sc_time_stamp().value();
        admit_until(now, now + m_lookahead);
        if (m_dispatch_empty) return;
        if (m_dispatch_held) {
            // The next frame: dispatch releases it once every ray of this one has finished.
            if (rays->releases() == m_held_at) wait(*rays->released());
            m_dispatch_held = false;
            continue;
        }
        if (!has_room()) {
            wait(m_room);
            continue;
        }
        const Cycle next = next_admit_issue(now);  // > now + lookahead: sleep until it is near
        wait(sc_core::sc_time::from_value(next - m_lookahead - now));
    }
}

Cycle RayBuffer::next_admit_issue(Cycle time) const {
    return std::max({time, m_admit_slots.top_time(), m_admit_next});
}

Cycle RayBuffer::fetch_ray_record(uint64_t ray_id, Cycle issue) {
    m_admit_next = issue + 1;
    const Cycle arrives = mem->access({m_map.ray(ray_id), sizeof(RayRecord), false, DataKind::ray, issue});
    m_admit_slots.set(m_admit_slots.top(), arrives);
    return arrives;
}

void RayBuffer::unindex(uint32_t t) {
    const auto& q = m_queues[t];
    if (q.empty()) return;
    if (m_config.policy == TreeletPolicy::oldest) m_by_age.erase({q.front().ready, t});
    else if (m_config.policy == TreeletPolicy::round_robin) m_nonempty.erase(t);
    // largest: index() overwrites the queue's key
}

void RayBuffer::index(uint32_t t) {
    const auto& q = m_queues[t];
    if (m_config.policy == TreeletPolicy::largest) {
        const uint32_t slot = uint32_t(m_queues.size()) - 1 - t;
        m_by_size.set(slot, q.empty() ? SizeTree::kNever : SizeTree::kNever - q.size());
        return;
    }
    if (q.empty()) return;
    if (m_config.policy == TreeletPolicy::oldest) m_by_age.insert({q.front().ready, t});
    else m_nonempty.insert(t);
}

int64_t RayBuffer::pick() {
    // The policy's first queue with at least `threshold` rays among the first few candidates; if
    // none is that long, its first queue anyway (draining). Waiting for a queue to fill instead was
    // tried and idles the machine: only running rays refill the queues (docs/treelets.md). With
    // `largest` the threshold therefore changes nothing: the largest queue is the choice either way.
    constexpr int kLook = 64;
    const uint64_t threshold = m_config.threshold;
    const TreeletPolicy policy = m_config.policy;
    int64_t first = -1, chosen = -1;
    auto consider = [&](uint32_t t) {
        if (first < 0) first = t;
        if (m_queues[t].size() >= threshold) chosen = t;
        return chosen >= 0;
    };
    if (policy == TreeletPolicy::largest) {
        if (!m_by_size.empty()) consider(uint32_t(m_queues.size()) - 1 - m_by_size.top());  // the largest decides
    } else if (policy == TreeletPolicy::oldest) {
        int k = 0;
        for (auto it = m_by_age.begin(); it != m_by_age.end() && k < kLook; ++it, ++k)
            if (consider(it->second)) break;
    } else {
        auto it = m_nonempty.upper_bound(m_round_robin);
        for (int k = 0; k < kLook && !m_nonempty.empty(); ++k, ++it) {
            if (it == m_nonempty.end()) it = m_nonempty.begin();
            if (consider(*it)) break;
        }
    }
    if (first < 0) return -1;
    if (chosen < 0) {
        chosen = first;
        ++m_drain_picks;
    }
    if (policy == TreeletPolicy::round_robin) m_round_robin = uint32_t(chosen);
    ++m_picks;
    m_picked_queue_rays += m_queues[chosen].size();
    return chosen;
}

bool RayBuffer::take(uint32_t consumer, Cycle time, RayState* ray, uint32_t* treelet, Cycle* ready,
                     bool may_switch) {
    int64_t& current = m_consumer_treelet[consumer];
    if (current < 0 || m_queues[current].empty()) {
        if (!may_switch) return false;
        current = pick();
        if (current < 0) return false;
    }
    Waiting& w = m_queues[current].front();
    *ray = std::move(w.state);
    *treelet = uint32_t(current);
    if (w.overflowed) {
        *ready = mem->access({m_map.ray_buffer(w.slot, m_state_bytes), m_state_bytes, false, DataKind::ray_buffer,
                              std::max(time, w.ready)});
        m_free_slots.push_back(w.slot);
        ++m_overflow_reads;
    } else {
        *ready = sram(std::max(time, w.ready));
        --m_occupancy;
        wake_admission();  // SRAM room
    }
    unindex(uint32_t(current));
    m_queues[current].pop_front();
    index(uint32_t(current));
    ++m_taken;
    return true;
}

Cycle RayBuffer::park(uint32_t treelet, RayState&& ray, Cycle time) {
    ++m_parked;
    push(treelet, std::move(ray), time, time);
    return m_queues[treelet].back().ready;
}

void RayBuffer::finished(Cycle time) {
    rays->ray_finished(time);  // dispatch counts a frame's rays to its barrier
    --m_in_machine;
    wake_admission();
}

void RayBuffer::wake_admission() {
    // (Module tests drive the buffer without a running simulation, where SystemC refuses events.)
    if (sc_core::sc_is_running()) m_room.notify();
}

const StatBlock& ray_buffer_stats() {
    static const StatBlock block{
        "model.ray_buffer",
        {
            {"ray_state_bytes", "bytes", "SRAM bytes one waiting ray occupies (ray, hit so far, id, on-chip stack)"},
            {"capacity_rays", "rays", "rays the SRAM holds: `buffer_kib * 1024 / ray_state_bytes`"},
            {"max_rays_in_flight", "rays", "admission limit in effect (`treelets.max_rays_in_flight`, 0 = capacity + ray contexts)"},
            {"max_occupancy", "rays", "most rays ever waiting in the SRAM; never above `capacity_rays` (tested)"},
            {"admitted", "rays", "new rays taken from dispatch into the root treelet's queue (= rays of the trace)"},
            {"parked", "rays", "times a ray left its treelet and joined another treelet's queue"},
            {"taken", "rays", "rays handed to ray contexts (`admitted + parked`)"},
            {"overflow_writes", "rays", "ray states written to memory because the SRAM was full"},
            {"overflow_reads", "rays", "ray states read back from memory"},
            {"overflow_bytes", "bytes", "`(overflow_writes + overflow_reads) * ray_state_bytes` (also in the memory levels as data kind `ray_buffer`)"},
            {"picks", "picks", "times a unit chose a new treelet queue"},
            {"drain_picks", "picks", "picks where no queue reached `treelets.threshold` (the policy's best queue ran anyway)"},
            {"avg_queue_rays_at_pick", "rays", "mean length of the chosen queue: how many rays share a treelet's load"},
            {"prefetch", "", "treelet prefetching's table (`treelets.prefetch`): `treelets_learnt` treelets rays have read lines in, `lines_learnt` their lines, `mean_lines` per such treelet (docs/treelets.md, \"Prefetching\")", false, true},
            {"treelets", "", "the partition: `count` treelets, `budget_bytes`, `mean_bytes` and `max_bytes` of a treelet, `max_depth` (deepest treelet level)"},
        }};
    return block;
}

nlohmann::json RayBuffer::stats_json() const {
    nlohmann::json j;
    StatsWriter(ray_buffer_stats(), j)
        .set("ray_state_bytes", m_state_bytes)
        .set("capacity_rays", m_capacity)
        .set("max_rays_in_flight", m_max_in_flight)
        .set("max_occupancy", m_max_occupancy)
        .set("admitted", m_admitted)
        .set("parked", m_parked)
        .set("taken", m_taken)
        .set("overflow_writes", m_overflows)
        .set("overflow_reads", m_overflow_reads)
        .set("overflow_bytes", (m_overflows + m_overflow_reads) * m_state_bytes)
        .set("picks", m_picks)
        .set("drain_picks", m_drain_picks)
        .set("avg_queue_rays_at_pick", m_picks ? double(m_picked_queue_rays) / double(m_picks) : 0.0)
        .set("treelets", m_treelets.partition_json());
    if (m_treelets.footprints()) j["prefetch"] = m_treelets.prefetch_json();
    ray_buffer_stats().check(j);
    return j;
}

RTSIM_REGISTER_STAT_BLOCK(ray_buffer_stats)

}  // namespace rtsim
