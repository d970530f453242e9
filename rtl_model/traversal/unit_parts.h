#pragma once
// Pieces every traversal unit kind shares, so no kind re-types them: temporal decoupling against
// SystemC time, moving a ray context's (or SIMT lane's, or packet's) accounted cycles forward by
// use and folding the rest of the run in as tail, the busy time, finishing a ray, and the stats
// every kind writes alike.
#include <algorithm>
#include <cstdint>

#include <systemc>

#include "rtl_model/common/interfaces.h"
#include "rtl_model/common/memory_map.h"
#include "rtl_model/common/stats.h"
#include "rtl_model/traversal/cycle_accounting.h"
#include "rtl_model/traversal/step_demand.h"

namespace rtsim {

/// Temporal decoupling (TLM-2.0 style): a unit runs ahead of SystemC time by at most a quantum,
/// then waits for the others to catch up. Called from the unit's SC_THREAD.
class QuantumSync {
public:
    explicit QuantumSync(uint32_t quantum_cycles) : m_quantum(quantum_cycles) {}
    void operator()(Cycle t) {
        if (t < m_synced + m_quantum) return;
        const uint64_t now = sc_core::sc_time_stamp().value();
        if (t > now) sc_core::wait(sc_core::sc_time::from_value(t - now));
        m_synced = t;
        ++m_syncs;
    }
    uint64_t syncs() const { return m_syncs; }

private:
    uint32_t m_quantum;
    Cycle m_synced = 0;
    uint64_t m_syncs = 0;
};

/// One context's (or lane's) cycles from `accounted` to `until` went to `use`.
inline void account_until(CycleAccount& account, Cycle& accounted, CycleUse use, Cycle until) {
    if (until <= accounted) return;
    account.add(use, until - accounted);
    accounted = until;
}

/// One context waited from `accounted` to `ready` for a read (split by where it went, `info`).
inline void account_read_until(CycleAccount& account, Cycle& accounted, Cycle ready, const AccessInfo& info) {
    if (ready <= accounted) return;
    account_memory(account, accounted, ready, info);
    accounted = ready;
}

/// The unit's account at the end of a run of `total` cycles: `account` plus, for each context
/// (anything with an `accounted` cycle), its cycles after that as tail, `weight` ray contexts each
/// (a packet holds `lanes`).
template <class Contexts>
CycleAccount with_tail(CycleAccount account, const Contexts& contexts, Cycle total, uint64_t weight = 1) {
    for (const auto& c : contexts)
        if (total > c.accounted) account.add(CycleUse::tail, (total - c.accounted) * weight);
    return account;
}

/// Cycles with at least one ray in the unit: enter() when a context takes a ray, leave() when
/// it gives it up.
class BusyTime {
public:
    void enter(Cycle t) {
        if (m_in++ == 0) m_since = t;
    }
    void leave(Cycle t) {
        if (--m_in == 0) m_cycles += t - m_since;  // a busy interval ends (may restart now)
    }
    Cycle cycles() const { return m_cycles; }

private:
    uint64_t m_in = 0;
    Cycle m_since = 0, m_cycles = 0;
};

/// What every unit kind counts alike, and the stats it writes from them.
struct UnitTally {
    uint64_t rays = 0, steps = 0, spill_writes = 0, spill_reads = 0, rejected = 0;
    Cycle finish = 0;  ///< cycle the unit finished its last ray
    BusyTime busy;

    /// Ray `r` is done at r.end: its hit record is written back (posted) and it is counted. The
    /// caller hands the result to the sink and tells the ray's source.
    void finish_ray(MemIf& mem, const MemoryMap& map, const RayResult& r) {
        mem.access({map.hit(r.id), sizeof(HitRecord), true, DataKind::hit, r.end});
        ++rays;
        finish = std::max(finish, r.end);
    }
    /// The keys every kind writes (unit_stats()).
    void write(StatsWriter& w, const QuantumSync& sync, const CycleAccount& account, Cycle total_cycles) const {
        w.set("rays", rays)
            .set("steps", steps)
            .set("busy_cycles", busy.cycles())
            .set("busy_fraction", total_cycles ? double(busy.cycles()) / double(total_cycles) : 0.0)
            .set("stack_spill_writes", spill_writes)
            .set("stack_spill_reads", spill_reads)
            .set("rejected_rays", rejected)
            .set("quantum_syncs", sync.syncs())
            .set("finish_cycle", finish)
            .set("cycle_accounting", account.to_json());
    }
};

/// The reads of one step (or warp step) issued together at `t`: the step waits for the slowest,
/// and where that one's time went is what its wait is accounted as (the first read's on ties).
class StepReads {
public:
    explicit StepReads(MemIf& mem, Cycle t) : m_mem(mem), m_t(t), m_ready(t) {}
    void read(uint64_t addr, uint32_t bytes, DataKind kind) {
        const Cycle done = m_mem.access({addr, bytes, false, kind, m_t, &m_info});
        if (done > m_ready || m_first) m_slowest = m_info;
        m_first = false;
        m_ready = std::max(m_ready, done);
    }
    void read(const Fetch& f) { read(f.addr, f.bytes, f.kind); }
    Cycle ready() const { return m_ready; }
    const AccessInfo& slowest() const { return m_slowest; }

private:
    MemIf& m_mem;
    Cycle m_t, m_ready;
    AccessInfo m_info, m_slowest;
    bool m_first = true;
};

/// Simulation speed only, no effect on the model: what a context's next step will touch on the
/// host (the stepper's plan, the structure's data its execute() reads, the L1's tags of its
/// first fetch), noted when the step is planned (all hot then) and prefetched shortly before
/// the step runs (the MIMD unit: one event before; the analytic level's profiler: a few steps
/// before), without chasing pointers. The stepper prefetched the data when it planned the
/// step, but other rays' events ran since and evicted it (the node load was the step's stall).
class HostAhead {
public:
    void note(const Stepper& stepper) {
        const StepPlan& plan = stepper.plan();
        m_plan = &plan;
        m_data = plan.done ? nullptr : plan.host;
        m_bytes = plan.host_bytes;
        m_fetch = plan.done || plan.fetch_count == 0 ? kNoFetch : plan.fetch[0].addr;
    }
    void prefetch(const MemIf& l1) const {
        prefetch_step();
        if (m_fetch != kNoFetch) l1.prefetch_host(m_fetch);
    }
    /// The plan and the structure's data only (a caller with no L1 model).
    void prefetch_step() const {
        __builtin_prefetch(m_plan);
        if (m_data) prefetch_range(m_data, m_bytes);
    }
    /// Address of the step's first fetch, or kNoFetch.
    uint64_t first_fetch() const { return m_fetch; }

    static constexpr uint64_t kNoFetch = ~0ull;

private:
    const void* m_plan = nullptr;
    const void* m_data = nullptr;
    uint32_t m_bytes = 0;
    uint64_t m_fetch = kNoFetch;
};

/// A step's stack traffic (docs/model.md, "Traversal stack") for the spill slots of `owner`:
/// entries beyond the on-chip stack written to memory (posted), spilled entries read back (the
/// ray waits for them). `before` runs before each access (a sync where the access is shared).
/// Returns when the last fill is back (at least `ready`); counts into *writes and *reads.
template <class Before>
Cycle issue_stack_traffic(MemIf& mem, const MemoryMap& map, const StepDemand& d, uint64_t owner, uint32_t bytes,
                          Cycle t, Cycle ready, uint64_t* writes, uint64_t* reads, Before&& before) {
    d.for_each_spill([&](uint32_t slot) {
        before();
        mem.access({map.stack(owner, slot, bytes), bytes, true, DataKind::stack, t});
        ++*writes;
    });
    d.for_each_fill([&](uint32_t slot) {
        before();
        ++*reads;
        ready = std::max(ready, mem.access({map.stack(owner, slot, bytes), bytes, false, DataKind::stack, t}));
    });
    return ready;
}

/// A unit with no ray in flight: false when dispatch is done; otherwise waits until dispatch
/// releases rays (the next frame's, held until this frame's last ray finishes, docs/model.md
/// "Frames"; or rays the in-flight frame loop held for their parents' shading), unless it did
/// since `release` (the count the unit last saw, updated), and returns true.
inline bool await_next_release(sc_core::sc_port<RaySourceIf>& rays, uint64_t& release) {
    const sc_core::sc_event* released = rays->released();
    if (rays->exhausted() || !released) return false;
    if (rays->releases() == release) sc_core::wait(*released);
    release = rays->releases();
    return true;
}

}  // namespace rtsim
