#pragma once
// Pieces every traversal unit kind shares, so no kind re-types them: temporal decoupling against
// SystemC time, and moving a ray context's (or SIMT lane's) accounted cycles forward by use.
#include <algorithm>
#include <cstdint>

#include <systemc>

#include "rtl_model/common/memory_map.h"
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

}  // namespace rtsim
