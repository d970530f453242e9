#pragma once
// The packet traversal unit, traversal.model = "packet": the unit's ray contexts are grouped
// traversal.packet.lanes at a time into packets, and a packet's rays share one traversal (Wald, Slusallek,
// Benthin & Wagner 2001): one stack, an active mask, one node fetch serving every active ray.
// Each packet drives the structure's packet stepper (traces/accel/packet_stepper.h), whose plan is
// the packet's step: its one fetch, and its operations the active rays' tests together; the
// step-demand function (../step_demand.h) costs it like any plan:
//
//   fetch rays -> [step: the node's (or leaf's) fetch, once for the packet -> ops: the active
//   rays' box or triangle tests on their pipelines at the pipeline's width, then the alpha tests
//   their hits call for]* -> write every ray's hit
//
// As in the MIMD unit, a scheduler takes one phase of one packet per issue_cycles, a step is two
// phases so requests to the private L1 and pipelines come in time order, and the unit runs ahead
// of SystemC time by at most quantum_cycles. A packet takes up to `lanes` rays from dispatch at
// once (fewer when dispatch runs short) and reads their records coalesced per line; it gives
// them back when its traversal ends (any-hit rays that found their hit stay masked off).
//
// The shared stack holds, per entry, the node, the packet's mask and each ray's entry distance
// (packet_stack_entry_bytes); `stack_entries` of them are on chip per packet, deeper ones spill.
// With traversal.packet.split_below (Benthin et al. 2012's hybrid), a packet whose active rays at
// a node fall below that fraction splits: the stepper then plans one ray's step at a time (one
// ray active), each ray finishing alone, so the same costing prices the single-ray tail.
// With traversal.packet.split_walks = lanes, the split rays instead walk at once, each on its own
// lane of the packet (the lanes its masked-off rays left free): every walking ray's lane is then
// scheduled as a context of its own (the stepper's lane_walker(), costed by the same step-demand
// function with a single ray's stack entry), and the packet takes new rays when its last lane is
// done. A lane's walk starts with its part of the shared stack on chip (the copy is not costed).
// Cycle accounting: a packet's `lanes` ray contexts spend each cycle on what the packet waits
// for, the rays masked off in its step (and empty lanes) as idle_lane; walking lanes their own
// cycles, and lanes done or without a walk idle_lane until the packet ends.
#include <cstdint>
#include <vector>

#include "rtl_model/traversal/packet/packet_config.h"
#include "rtl_model/traversal/scheduled_unit.h"
#include "rtl_model/traversal/simt/coalescer.h"
#include "rtl_model/traversal/unit_parts.h"
#include "traces/accel/packet_stepper.h"

namespace rtsim {

/// Bytes of a packet's stack entry: a structure entry of `entry_bytes` (a 4-byte node index and
/// one ray's distances: a BVH's entry distance, a kd-tree's interval, an octree's cell), each
/// further ray's distances, and the active mask.
inline uint32_t packet_stack_entry_bytes(uint32_t entry_bytes, uint32_t lanes) {
    return entry_bytes + (entry_bytes - 4) * (lanes - 1) + (lanes + 7) / 8;
}

class PacketUnit : public ScheduledUnit {
public:
    SC_HAS_PROCESS(PacketUnit);
    PacketUnit(sc_core::sc_module_name name, const UnitSetup& setup, uint32_t index);

    CycleAccount cycle_account(Cycle total_cycles) const override;
    nlohmann::json stats_json(Cycle total_cycles) const override;
    /// The kind's own stats (model.units.<unit> beside unit_stats()), bound to their counters.
    static const StatTable<PacketUnit>& kind_stats();

private:
    enum class Phase : uint8_t { step, ops };
    /// A ray walking alone on its lane after its packet split (split_walks = lanes).
    struct Lane {
        StackSplit stack;
        StepDemand demand;
        Phase phase = Phase::step;
        Cycle accounted = 0;  ///< this lane's cycles up to here are in m_account
    };
    struct Packet {
        std::unique_ptr<PacketStepper> stepper;
        std::vector<uint64_t> ids;  ///< trace indices of its rays
        Cycle start = 0;
        StackSplit stack;
        StepDemand demand;
        Phase phase = Phase::step;
        bool active = false;
        uint32_t weight = 0;  ///< rays taking part in what the packet does now (the rest: idle_lane)
        Cycle accounted = 0;  ///< its lanes' cycles up to here are in m_account
        std::vector<Lane> lanes;  ///< split_walks = lanes: its lanes' walks
        LaneMask walking = 0;     ///< lanes still walking alone (0: the packet steps)
    };

    void run();
    void fill_idle_packets(Cycle t);
    bool start_packet(uint32_t p, Cycle t);
    void advance(uint32_t p, Cycle t);
    void step(uint32_t p, Cycle t);
    void run_ops(uint32_t p, Cycle t);
    void finish_packet(uint32_t p, Cycle t);
    /// split_walks = lanes: the slot of packet p's lane i, and the lanes' walks.
    uint32_t lane_slot(uint32_t p, uint32_t i) const { return uint32_t(m_packets.size()) + p * m_packet.lanes + i; }
    void launch_lanes(uint32_t p, Cycle t);
    void advance_lane(uint32_t p, uint32_t i, Cycle t);
    void lane_done(uint32_t p, uint32_t i, Cycle t);
    /// Packet p's lanes' cycles from its last accounted cycle to `until`: `weight` of them on
    /// `use`, the others idle_lane.
    void account(uint32_t p, CycleUse use, Cycle until);
    /// Packet p waited to `ready` for a read (split by where it went, `info`).
    void account_read(uint32_t p, Cycle ready, const AccessInfo& info);

    const PacketConfig& m_packet;
    const StepCosts m_lane_costs;  ///< a lane walking alone: the machine's costs, a single ray's stack entry
    std::vector<Packet> m_packets;
    LineCoalescer m_coalescer;  ///< a new packet's ray records, per line
    uint64_t m_packets_traced = 0, m_packet_steps = 0, m_node_fetches = 0, m_active_rays = 0;
    uint64_t m_splits = 0, m_split_steps = 0;  ///< the hybrid: packets that split, steps of their single rays
    std::vector<uint64_t> m_active_histogram;  ///< packet steps by active rays (0 .. lanes)
    std::vector<RayResult> m_results;          ///< scratch: a finished packet's results
    std::vector<Ray> m_rays;
    std::vector<TraversalMode> m_modes;
};

}  // namespace rtsim
