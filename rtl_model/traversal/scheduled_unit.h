#pragma once
// What every traversal unit kind holds (MIMD, SIMT, packets; docs/architecture.md, "Adding a
// traversal unit kind"): its setup, the queue of its contexts', warps' or packets' next phases,
// its scheduler's next free cycle, its quantum sync with SystemC time, the dispatch frame it last
// filled from, its tally, its cycle account and its stack prefetcher. The kinds differ in what they schedule and how
// a phase runs, not in these.
#include <cstdint>

#include "rtl_model/traversal/context_queue.h"
#include "rtl_model/traversal/cycle_accounting.h"
#include "rtl_model/traversal/stack_prefetcher.h"
#include "rtl_model/traversal/traversal_unit.h"
#include "rtl_model/traversal/unit_parts.h"

namespace rtsim {

class ScheduledUnit : public TraversalUnit {
public:
    Cycle finish_cycle() const override { return m_tally.finish; }
    uint64_t rays_done() const override { return m_tally.rays; }

protected:
    /// `slots`: the contexts, warps or packets the queue orders; `costs`: the unit's step costs.
    ScheduledUnit(sc_core::sc_module_name name, const UnitSetup& setup, uint32_t index, uint32_t slots,
                  const StepCosts& costs)
        : TraversalUnit(name),
          m_config(setup.config),
          m_ctx(setup.context),
          m_map(setup.map),
          m_steppers(setup.steppers),
          m_costs(costs),
          m_index(index),
          m_events(slots),
          m_sync(setup.context.quantum_cycles) {}

    /// One stack prefetcher stream per ray context or lane (`streams`).
    void attach_stack_prefetch(uint32_t streams) {
        m_stack_prefetch.configure(m_config.stack_prefetch, streams, m_ctx.line_bytes);
    }

    const TraversalConfig& m_config;
    UnitContext m_ctx;
    const MemoryMap& m_map;
    StepperPool& m_steppers;
    const StepCosts m_costs;
    uint32_t m_index;
    ContextQueue m_events;  ///< each slot's next phase, earliest first
    QuantumSync m_sync;
    Cycle m_sched_free = 0;  ///< the scheduler's next free cycle
    uint64_t m_release = 0;  ///< the dispatch's release count when the unit last filled its slots
    UnitTally m_tally;
    CycleAccount m_account;
    StackPrefetcher m_stack_prefetch;  ///< traversal.stack_prefetch (TTP); off when 0
};

}  // namespace rtsim
