#include "rtl_model/traversal/traversal_unit.h"

namespace rtsim {

const StatBlock& unit_stats() {
    static const StatBlock block{
        "model.units.<unit>",
        {
            {"rays", "rays", "rays this unit finished"},
            {"steps", "steps", "scheduler steps: per ray one for its ray fetch and end, per traversal step two (fetch, operations)"},
            {"busy_cycles", "cycles", "cycles with at least one ray context active; `null` at analytic", true},
            {"busy_fraction", "fraction", "`busy_cycles / summary.cycles`; `null` at analytic", true},
            {"stack_spill_writes", "entries", "stack entries pushed beyond `traversal.stack_entries` and written to memory"},
            {"stack_spill_reads", "entries", "spilled entries read back when the on-chip stack ran empty"},
            {"rejected_rays", "rays", "rays that failed the validity check (NaN, zero direction, ...) and traced nothing"},
            {"quantum_syncs", "count", "times the unit waited for SystemC time (temporal decoupling, `quantum_cycles`); `null` at analytic", true},
            {"finish_cycle", "cycle", "cycle this unit finished its last ray; `null` at analytic", true},
            {"cycle_accounting", "context-cycles", "`{use: cycles}`: where this unit's ray contexts spent their cycles ([uses](#modelcycle_accounting-why-is-it-slow-where-context-time-goes)); they sum to `ray_contexts x summary.cycles` exactly; timed levels only", false, true},
            {"rays_taken", "rays", "treelet scheduling only: rays it took from the ray buffer", false, true},
            {"rays_parked", "rays", "treelet scheduling only: rays it parked in another treelet's queue", false, true},
            {"idle_polls", "count", "treelet scheduling only: times it found no ray and looked again after `treelets.idle_poll_cycles`", false, true},
        }};
    return block;
}

}  // namespace rtsim
