#pragma once
// The MIMD traversal unit, traversal.model = "mimd" (in the spirit of TRaX/STRaTA, Kopta et al. 2013): `ray_contexts` rays in
// flight, each stepping its own stepper (traces/accel/stepper.h) on its own, no lock-step. The
// unit knows no acceleration structure: each step's plan says what to fetch and which operations
// to run (docs/architecture.md, the acceleration-structure seam), and the step-demand function
// (../step_demand.h) says what it costs. A step takes two phases so the unit's requests to its
// private L1 and pipelines come in time order:
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
// With treelet prefetching, the unit's steps teach the footprint table and a treelet the unit
// starts is prefetched (../treelet_prefetcher.h).
#include <cstdint>
#include <vector>

#include "rtl_model/traversal/scheduled_unit.h"
#include "rtl_model/traversal/treelet_prefetcher.h"
#include "rtl_model/traversal/unit_parts.h"

namespace rtsim {

class MimdUnit : public ScheduledUnit {
public:
    SC_HAS_PROCESS(MimdUnit);
    MimdUnit(sc_core::sc_module_name name, const UnitSetup& setup, uint32_t index);

    CycleAccount cycle_account(Cycle total_cycles) const override;
    nlohmann::json stats_json(Cycle total_cycles) const override;

private:
    enum class Phase : uint8_t { fetch_ray, step, ops };
    struct Context {
        RayState ray;              ///< stepper, ray id, start cycle, stack split
        StepDemand demand;         ///< the step in flight: costed when its fetches issue
        Phase phase = Phase::step;
        uint32_t treelet = kNoTreelet;  ///< treelet the ray is traversing (treelet scheduling or prefetching)
        bool active = false;
        Cycle accounted = 0;       ///< its cycles up to here are in m_account
    };

    void run();
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
    Cycle stack_traffic(uint32_t c, Cycle t, Cycle ready);
    void schedule(uint32_t c, Cycle t) { m_events.schedule(c, t); }
    /// Context c's cycles from its last accounted cycle to `until` went to `use`.
    void account(uint32_t c, CycleUse use, Cycle until) {
        account_until(m_account, m_contexts[c].accounted, use, until);
    }
    /// Context c waited from its last accounted cycle to `ready` for a read (split by `info`).
    void account_read(uint32_t c, Cycle ready, const AccessInfo& info) {
        account_read_until(m_account, m_contexts[c].accounted, ready, info);
    }

    const TreeletMap* m_treelets;  ///< treelet scheduling or prefetching; else null
    std::vector<Context> m_contexts;
    std::vector<HostAhead> m_ahead;  ///< per context: its next step's host data (speed only; kept
                                     ///< apart from the contexts so the look-up stays in the host's cache)
    bool m_treelet_mode = false;
    Cycle m_next_fill = 0;
    uint64_t m_parks = 0, m_takes = 0, m_idle_polls = 0;
    TreeletPrefetcher m_prefetcher;
};

}  // namespace rtsim
