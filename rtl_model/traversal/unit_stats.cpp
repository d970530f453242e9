#include "rtl_model/traversal/unit_stats.h"

#include <map>

#include "rtl_model/traversal/unit_kind.h"

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
            {"prefetch", "", "treelet prefetching only (`treelets.prefetch`, with or without treelet queues): `entries` treelets the unit's rays entered and it prefetched, `queued` lines queued for them, `sent` lines sent to the cache, `cancelled` lines dropped unsent (the unit moved to another treelet, or past the engine's queue), `waits` times the target had no free MSHR and the engine waited", false, true},
            {"stack_prefetch", "", "stack-driven prefetching only (`traversal.stack_prefetch`, TTP): `triggers` steps that popped (pushed nothing, the stack shrank) and prefetched their stack's top entries, `sent` lines sent to the L1 (a line already there is sent and found), `dropped` lines the L1 had no free MSHR for, `repeats` lines the stream had just sent; accuracy and coverage are the L1's `prefetch` stats", false, true},
            {"lane_slots", "lane-steps", "kinds that step groups of rays in lock-step (simt warps, packets): group steps x rays per group", false, true},
            {"active_lanes", "lane-steps", "kinds that step groups in lock-step: rays that took part, summed over group steps", false, true},
            {"simd_efficiency", "fraction", "kinds that step groups in lock-step: `active_lanes / lane_slots` (Aila & Laine 2009's SIMD efficiency; for packets, `packet_occupancy / traversal.packet.lanes`)", false, true},
        }};
    return block;
}

const StatBlock& unit_stats_of(const std::string& kind) {
    static std::map<std::string, StatBlock> merged;  // made once per kind, on first use
    auto it = merged.find(kind);
    if (it == merged.end())
        it = merged.emplace(kind, merged_block("model.units.<unit>", {&unit_stats(), unit_kind(kind).stats})).first;
    return it->second;
}

RTSIM_REGISTER_STAT_BLOCK(unit_stats)

}  // namespace rtsim
