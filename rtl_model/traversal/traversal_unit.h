#pragma once
// What every kind of traversal unit is to the rest of the machine (docs/model.md, "Traversal
// units"): ports to dispatch, its memory (the L1), one pipeline port per operation kind, the hit
// sink and, with treelet scheduling, the ray buffer; and the stats it reports. Kinds register
// themselves by name (traversal.model; unit_kind.h); each costs its steps with the step-demand
// function (step_demand.h), so none re-types a timing rule.
#include <cstdint>

#include <nlohmann/json.hpp>
#include <systemc>

#include "rtl_model/common/interfaces.h"
#include "rtl_model/common/memory_map.h"
#include "rtl_model/common/ray_state.h"
#include "rtl_model/common/stats.h"
#include "rtl_model/common/treelet_map.h"
#include "rtl_model/traversal/cycle_accounting.h"
#include "rtl_model/traversal/step_demand.h"
#include "rtl_model/traversal/traversal_config.h"
#include "rtl_model/traversal/unit_stats.h"

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
    uint32_t line_bytes = 64;  ///< the L1's line size: a SIMT warp coalesces its reads per line
};

/// Everything a unit is built from (one per machine; every unit of it shares it).
struct UnitSetup {
    const TraversalConfig& config;
    UnitContext context;
    const MemoryMap& map;
    StepperPool& steppers;
    StepCosts costs;
    /// The treelet partition (and the prefetchers' footprint table), with treelet scheduling or
    /// prefetching; null otherwise.
    const TreeletMap* treelets = nullptr;
};

class TraversalUnit : public sc_core::sc_module {
public:
    sc_core::sc_port<RaySourceIf> rays;
    sc_core::sc_port<MemIf> mem;
    /// One port per operation kind; bound for the kinds the structure issues (Top::build_pipelines).
    sc_core::sc_vector<sc_core::sc_port<PipeIf, 1, sc_core::SC_ZERO_OR_MORE_BOUND>> pipes;
    sc_core::sc_port<RaySinkIf> sink;
    sc_core::sc_port<RayBufferIf, 1, sc_core::SC_ZERO_OR_MORE_BOUND> ray_buffer;  ///< treelet mode

    /// Cycle the unit finished its last ray.
    virtual Cycle finish_cycle() const = 0;
    virtual uint64_t rays_done() const = 0;
    /// Context-cycles by use up to `total_cycles` (contexts idle at the end count as tail).
    virtual CycleAccount cycle_account(Cycle total_cycles) const = 0;
    virtual nlohmann::json stats_json(Cycle total_cycles) const = 0;

protected:
    explicit TraversalUnit(sc_core::sc_module_name name)
        : sc_core::sc_module(name), pipes("pipes", kOpKindCount) {}
};

}  // namespace rtsim
