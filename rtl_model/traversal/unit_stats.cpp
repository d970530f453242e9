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
            {"prefetch", "", "treelet prefetching only (`treelets.prefetch`): `entries` treelets the unit started and prefetched, `queued` lines queued for them, `sent` lines sent to the cache, `cancelled` lines dropped unsent when the unit moved to another treelet, `waits` times the target had no free MSHR and the engine waited", false, true},
            {"warp_steps", "steps", "simt only: warp steps (one operation kind for the warp, or the new rays' record fetch)", false, true},
            {"ray_fetch_steps", "steps", "simt only: warp steps that fetched new rays' records", false, true},
            {"lane_slots", "lane-steps", "simt: `warp_steps x traversal.lanes`; packet: `packet_steps x traversal.lanes`", false, true},
            {"active_lanes", "lane-steps", "simt: lanes that stepped, summed over warp steps; packet: active rays summed over packet steps", false, true},
            {"simd_efficiency", "fraction", "simt and packet: `active_lanes / lane_slots` (Aila & Laine 2009's SIMD efficiency; for packets, `packet_occupancy / traversal.lanes`)", false, true},
            {"active_lane_histogram", "steps", "simt only: warp steps by active lanes, index 0 .. `traversal.lanes`", false, true},
            {"simd_efficiency_by_kind", "fraction", "simt only: `{ray kind: lanes of that kind that stepped / lanes holding a ray of that kind}` over warp steps (empty lanes are in no kind)", false, true},
            {"simd_efficiency_over_time", "fraction", "simt only: `[{cycle, value}]`, active lanes / lane slots of the warp steps issued in each interval (at most 256 points)", false, true},
            {"lane_requests", "requests", "simt only: reads the stepping lanes asked for (a MIMD unit's requests for the same steps)", false, true},
            {"packets", "packets", "packet only: packets traced (each up to `traversal.lanes` rays taken from dispatch together)", false, true},
            {"packet_steps", "steps", "packet only: packet steps (one node or leaf fetch serving the packet's active rays)", false, true},
            {"packet_node_fetches", "fetches", "packet only: node fetches, one per packet node step", false, true},
            {"node_fetches_per_packet", "fetches", "packet only: `packet_node_fetches / packets`", false, true},
            {"packet_occupancy", "rays", "packet only: active rays per packet step (`active_lanes / packet_steps`; Wald et al. 2001's packets keep it near `traversal.lanes` on coherent rays)", false, true},
            {"packet_active_histogram", "steps", "packet only: packet steps by active rays, index 0 .. `traversal.lanes`", false, true},
            {"packet_splits", "packets", "packet only: packets that split into single rays (`traversal.packet_split_below`, Benthin et al. 2012's hybrid)", false, true},
            {"packet_split_steps", "steps", "packet only: of `packet_steps`, the single-ray steps after a split (one ray active each)", false, true},
            {"coalesced_requests", "requests", "simt only: read requests after coalescing a warp step's reads per L1 line", false, true},
        }};
    return block;
}

}  // namespace rtsim
