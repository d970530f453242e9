#pragma once
// The treelet ray buffer (Aila & Karras 2010; in hardware, STRaTA by Kopta et al. 2013): an SRAM
// of `buffer_kib` holding the state of rays waiting for a treelet, one FIFO queue per treelet.
//
// - New rays are admitted from dispatch into the queue of their first step's treelet while fewer than
//   max_rays_in_flight rays are in the machine (default: what the SRAM and the ray contexts hold,
//   so nothing overflows); their ray record is read from memory on the way in. Admitting more
//   makes longer queues (more rays share each treelet load) at the price of overflow traffic.
//   An admission engine (a process of its own) streams the record reads in time: one per cycle,
//   at most admit_outstanding in flight, at most a quantum ahead of SystemC time.
// - A unit whose treelet queue runs dry asks the scheduler for another: by policy (largest queue,
//   oldest waiting ray, round robin) among queues of at least `threshold` rays, or — when no
//   queue is that long — the policy's best non-empty queue, so the machine always makes progress
//   (with `largest` the threshold changes nothing: the largest queue wins either way).
// - A ray that needs a node of another treelet is parked in that treelet's queue. If the SRAM is
//   full it overflows: its state is written to memory (data kind ray_buffer) and read back when
//   it is taken; the traffic goes through the L2 and DRAM and is counted.
// Requests come from units that run ahead of each other within a quantum; the queues are updated
// in call order and each parked ray carries the cycle its state is ready, so no ray is used
// before it exists.
#include <cstdint>
#include <deque>
#include <memory>
#include <set>
#include <vector>

#include <nlohmann/json.hpp>
#include <systemc>

#include "rtl_model/common/calendar.h"
#include "rtl_model/common/memory_map.h"
#include "rtl_model/common/min_tree.h"
#include "rtl_model/common/ray_state.h"
#include "rtl_model/common/stats.h"
#include "rtl_model/common/treelet_map.h"
#include "rtl_model/ray_buffer/ray_buffer_config.h"
#include "traces/accel/locality.h"

namespace rtsim {

/// The ray buffer's stats (model.ray_buffer).
const StatBlock& ray_buffer_stats();

class RayBuffer : public sc_core::sc_module, public RayBufferIf {
public:
    sc_core::sc_port<RaySourceIf> rays;  ///< dispatch
    sc_core::sc_port<MemIf> mem;          ///< ray records in, overflow out (the L2)

    /// units x ray_contexts: the rays the traversal units hold; consumers: what takes rays of one
    /// treelet at a time (take()); state_bytes: ray_state_bytes(). lookahead: how far past SystemC
    /// time the admission engine may issue reads (the units' quantum: 1 cycle at the detailed
    /// level, where the L2 and DRAM see requests in time order).
    RayBuffer(sc_core::sc_module_name name, const TreeletConfig& config, const TreeletMap& treelets,
              const MemoryMap& map, StepperPool& steppers, uint32_t units, uint32_t ray_contexts, uint32_t consumers,
              uint32_t state_bytes, Cycle lookahead);

    bool take(uint32_t consumer, Cycle time, RayState* ray, uint32_t* treelet, Cycle* ready,
              bool may_switch = true) override;
    /// The admission engine up to `horizon`, asked at `time`: issues, in order, every ray-record
    /// read that can leave at or before `horizon` (one per cycle from `time` on, at most
    /// admit_outstanding in flight) while the machine has room, and queues those rays. The
    /// engine's own process calls it with horizon = SystemC time + lookahead; tests call it.
    void admit_until(Cycle time, Cycle horizon);
    Cycle park(uint32_t treelet, RayState&& ray, Cycle time) override;
    void finished(Cycle time) override;
    bool done() const override { return m_dispatch_empty && m_in_machine == 0; }

    uint64_t capacity_rays() const { return m_capacity; }
    uint64_t max_occupancy() const { return m_max_occupancy; }
    nlohmann::json stats_json() const;

private:
    struct Waiting {
        RayState state;
        Cycle ready;       ///< cycle the state is in the buffer (or in memory, if overflowed)
        bool overflowed;   ///< state lives in memory, not in the SRAM
        uint64_t slot;     ///< overflow slot
    };
    SC_HAS_PROCESS(RayBuffer);
    /// The admission engine's process: streams ray-record reads in time (docs/treelets.md).
    void admission();
    bool has_room() const;
    void wake_admission();  ///< a ray left the machine or the SRAM: the engine may go on
    /// Cycle the admission engine can issue its next ray-record read, asked at `time`.
    Cycle next_admit_issue(Cycle time) const;
    /// Reads a new ray's record at `issue` (= next_admit_issue()) in the earliest free read slot:
    /// one read issued per cycle, at most admit_outstanding in flight (a burst of thousands of
    /// reads at one cycle would swamp the L2's MSHRs). Returns the cycle the record arrives.
    Cycle fetch_ray_record(uint64_t ray_id, Cycle issue);
    void unindex(uint32_t treelet);
    void index(uint32_t treelet);
    void push(uint32_t treelet, RayState&& ray, Cycle ready, Cycle time);
    int64_t pick();
    Cycle sram(Cycle time);

    const TreeletConfig& m_config;
    const TreeletMap& m_treelets;
    const MemoryMap& m_map;
    StepperPool& m_steppers;
    uint32_t m_state_bytes;
    uint64_t m_capacity;
    uint64_t m_max_in_flight;
    std::vector<std::deque<Waiting>> m_queues;
    std::vector<int64_t> m_consumer_treelet;  ///< each consumer's current treelet (-1: none yet)
    MinTree m_admit_slots;             ///< completion cycle of each admission read slot
    Cycle m_admit_next = 0;            ///< earliest cycle the next admission read can issue
    Cycle m_lookahead;                 ///< the engine issues reads at most this far past SystemC time
    sc_core::sc_event m_room;          ///< a ray left the machine or the SRAM: admission may go on
    BandwidthCalendar m_sram;
    std::vector<uint64_t> m_free_slots;
    uint64_t m_next_slot = 0;
    uint32_t m_round_robin = 0;
    // Ordered views of the non-empty queues for the scheduler (only the policy's is kept).
    // largest: a MinTree keyed by (kNever - size) over slots T-1-t, so its top is the largest
    // queue and, among equal sizes, the highest treelet id (O(log T) per change, no allocation).
    using SizeTree = BasicMinTree<24>;
    SizeTree m_by_size;
    std::set<std::pair<Cycle, uint32_t>> m_by_age;  ///< oldest front first
    std::set<uint32_t> m_nonempty;                  ///< by treelet id
    bool m_dispatch_empty = false;
    bool m_dispatch_held = false;  ///< dispatch holds the next frame's rays (a frame barrier)
    uint64_t m_held_at = 0;        ///< dispatch's releases when it held them
    uint64_t m_occupancy = 0, m_max_occupancy = 0, m_in_machine = 0;
    uint64_t m_admitted = 0, m_parked = 0, m_taken = 0, m_overflows = 0, m_overflow_reads = 0;
    uint64_t m_picks = 0, m_drain_picks = 0, m_picked_queue_rays = 0;
};

}  // namespace rtsim
