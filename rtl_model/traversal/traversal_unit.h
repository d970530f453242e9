#pragma once
// A MIMD traversal unit (in the spirit of TRaX/STRaTA, Kopta et al. 2013): `ray_contexts` rays in
// flight, each stepping its own stepper (traces/accel/stepper.h) on its own, no lock-step. The
// unit knows no acceleration structure: each step's plan says what to fetch and which operations
// to run (docs/architecture.md, the acceleration-structure seam). A step takes two phases so the
// unit's requests to its private L1 and pipelines come in time order:
//
//   fetch ray -> [step: issue the plan's fetches -> ops: run the plan's operations on their
//   pipelines (box, triangle, ...), then any the results call for (alpha tests)]* -> write hit
//
// A scheduler picks the context whose next phase is ready earliest (one step per issue_cycles).
// The on-chip stack holds `stack_entries` entries per ray; pushes beyond spill to memory (posted
// writes), pops of spilled entries read them back (the ray waits), all counted as stack traffic.
// The unit runs ahead of SystemC time by at most quantum_cycles, then waits (temporal decoupling).
//
// With treelet scheduling (ray_buffer bound), contexts take rays from the ray buffer queue of the
// unit's current treelet instead of from dispatch; a ray whose next step lies in another treelet
// is parked in that treelet's queue and the context takes the next ray. Traversal order, hits and
// work counts do not change: the stepper is the same, the ray only waits in between.
#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>
#include <systemc>

#include "rtl_model/common/interfaces.h"
#include "rtl_model/common/memory_map.h"
#include "rtl_model/common/ray_state.h"
#include "rtl_model/traversal/context_queue.h"
#include "rtl_model/traversal/cycle_accounting.h"
#include "rtl_model/traversal/traversal_config.h"

namespace rtsim {

/// What a unit needs from beyond its own config, set by the top level from the config tree.
struct UnitContext {
    uint32_t quantum_cycles = 256;    ///< how far the unit may run ahead of SystemC time
    uint32_t dispatch_latency = 2;    ///< cycles to receive a ray from dispatch
    uint32_t idle_poll_cycles = 32;   ///< treelet mode: how often an idle unit looks for rays
    /// false: a step that touches only the unit's private blocks (its pipelines, no stack spill)
    /// does not synchronise with SystemC time first (the detailed level with private pipelines:
    /// shared blocks still see every request in time order, at half the synchronisations).
    bool sync_private_steps = true;
};

class TraversalUnit : public sc_core::sc_module {
public:
    sc_core::sc_port<RaySourceIf> rays;
    sc_core::sc_port<MemIf> mem;
    /// One port per operation kind; bound for the kinds the structure issues (Top::build_pipelines).
    sc_core::sc_vector<sc_core::sc_port<PipeIf, 1, sc_core::SC_ZERO_OR_MORE_BOUND>> pipes;
    sc_core::sc_port<RaySinkIf> sink;
    sc_core::sc_port<RayBufferIf, 1, sc_core::SC_ZERO_OR_MORE_BOUND> ray_buffer;  ///< treelet mode

    SC_HAS_PROCESS(TraversalUnit);
    TraversalUnit(sc_core::sc_module_name name, const TraversalConfig& config, const UnitContext& context,
                  const MemoryMap& map, StepperPool& steppers, uint32_t index);

    Cycle finish_cycle() const { return m_finish; }
    uint64_t rays_done() const { return m_rays; }
    /// Context-cycles by use up to `total_cycles` (contexts idle at the end count as tail).
    CycleAccount cycle_account(Cycle total_cycles) const;
    nlohmann::json stats_json(Cycle total_cycles) const;

private:
    enum class Phase : uint8_t { fetch_ray, step, ops };
    struct Context {
        RayState ray;              ///< stepper, ray id, start cycle, stack bookkeeping
        Phase phase = Phase::step;
        uint32_t treelet = 0;      ///< treelet the ray is traversing (treelet mode)
        bool active = false;
        Cycle accounted = 0;       ///< its cycles up to here are in m_account
    };

    void run();
    void sync(Cycle t);
    bool start_ray(uint32_t c, Cycle t);
    bool take_parked_ray(uint32_t c, Cycle t);
    void park_ray(uint32_t c, uint32_t treelet, Cycle t);
    void fill_idle_contexts(Cycle t);
    void activate(uint32_t c, Cycle t);
    void deactivate(uint32_t c, Cycle t);
    void advance(uint32_t c, Cycle t);
    void step(uint32_t c, Cycle t);
    void run_ops(uint32_t c, Cycle t);
    void finish_ray(uint32_t c, Cycle t);
    Cycle stack_traffic(uint32_t c, int before, Cycle t, Cycle ready);
    void schedule(uint32_t c, Cycle t) { m_events.schedule(c, t); }
    /// Context c's cycles from its last accounted cycle to `until` went to `use`.
    void account(uint32_t c, CycleUse use, Cycle until);
    /// Context c waited from its last accounted cycle to `ready` for a read (split by `info`).
    void account_read(uint32_t c, Cycle ready, const AccessInfo& info);

    const TraversalConfig& m_config;
    UnitContext m_ctx;
    const MemoryMap& m_map;
    StepperPool& m_steppers;
    uint32_t m_index;
    std::vector<Context> m_contexts;
    ContextQueue m_events;  ///< each context's next phase, earliest first
    Cycle m_sched_free = 0;
    Cycle m_synced = 0;
    Cycle m_finish = 0;
    uint32_t m_active = 0;
    Cycle m_busy_since = 0, m_busy_cycles = 0;
    uint64_t m_rays = 0, m_steps = 0, m_spill_writes = 0, m_spill_reads = 0, m_rejected = 0, m_syncs = 0;
    bool m_treelet_mode = false;
    uint32_t m_frame = 0;  ///< the dispatch frame this unit last filled its contexts from
    Cycle m_next_fill = 0;
    uint64_t m_parks = 0, m_takes = 0, m_idle_polls = 0;
    CycleAccount m_account;
};

}  // namespace rtsim
