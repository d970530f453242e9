#pragma once
// A MIMD traversal unit (in the spirit of TRaX/STRaTA, Kopta et al. 2013): `ray_contexts` rays in
// flight, each stepping the reference traversal stepper (traces/isect/traversal.h) on its own —
// no lock-step. Each step is split into phases so that the unit's requests to its private L1 and
// pipelines come in time order:
//
//   fetch ray -> [fetch node (64 B) -> box pipeline -> decide]* / [fetch leaf triangles ->
//   triangle pipeline -> (alpha any-hit stage) -> decide]* -> write hit
//
// A scheduler picks the context whose next phase is ready earliest (one step per issue_cycles).
// The on-chip stack holds `stack_entries` entries per ray; pushes beyond spill to memory (posted
// writes), pops of spilled entries read them back (the ray waits), all counted as stack traffic.
// The unit runs ahead of SystemC time by at most quantum_cycles, then waits (temporal decoupling).
//
// With treelet scheduling (ray_buffer bound), contexts take rays from the ray buffer queue of the
// unit's current treelet instead of from dispatch; a ray whose next node lies in another treelet
// is parked in that treelet's queue and the context takes the next ray. Traversal order, hits and
// work counts do not change: the stepper is the same, the ray only waits in between.
#include <cstdint>
#include <queue>
#include <vector>

#include <nlohmann/json.hpp>
#include <systemc>

#include "rtl_model/common/interfaces.h"
#include "rtl_model/common/ray_state.h"
#include "rtl_model/top/memory_image.h"
#include "sim/config/config.h"
#include "traces/isect/traversal.h"

namespace rtsim {

class TraversalUnit : public sc_core::sc_module {
public:
    sc_core::sc_port<RaySourceIf> rays;
    sc_core::sc_port<MemIf> mem;
    sc_core::sc_port<PipeIf> box;
    sc_core::sc_port<PipeIf> triangle;
    sc_core::sc_port<PipeIf, 1, sc_core::SC_ZERO_OR_MORE_BOUND> anyhit;  ///< only with MASK triangles
    sc_core::sc_port<RaySinkIf> sink;
    sc_core::sc_port<RayBufferIf, 1, sc_core::SC_ZERO_OR_MORE_BOUND> ray_buffer;  ///< treelet mode

    SC_HAS_PROCESS(TraversalUnit);
    TraversalUnit(sc_core::sc_module_name name, const SimConfig& config, const MemoryImage& image, uint32_t index);

    Cycle finish_cycle() const { return m_finish; }
    uint64_t rays_done() const { return m_rays; }
    nlohmann::json stats_json(Cycle total_cycles) const;

private:
    enum class Phase : uint8_t { fetch_ray, step, boxes, triangles };
    struct Context {
        RayState ray;              ///< stepper, ray id, start cycle, stack bookkeeping
        Phase phase = Phase::step;
        uint32_t treelet = 0;      ///< treelet the ray is traversing (treelet mode)
        bool active = false;
    };
    struct Event {
        Cycle time;
        uint32_t context;
        bool operator>(const Event& o) const { return time > o.time || (time == o.time && context > o.context); }
    };

    void run();
    void sync(Cycle t);
    bool start_ray(uint32_t c, Cycle t);
    bool take_parked_ray(uint32_t c, Cycle t);
    void park_ray(uint32_t c, uint32_t treelet, Cycle t);
    void fill_idle_contexts(Cycle t);
    void activate(uint32_t c, Cycle t);
    void advance(uint32_t c, Cycle t);
    void step(uint32_t c, Cycle t);
    void finish_ray(uint32_t c, Cycle t);
    Cycle stack_traffic(uint32_t c, int before, Cycle t, Cycle ready);
    void schedule(uint32_t c, Cycle t) { m_events.push(Event{t, c}); }

    const SimConfig& m_config;
    const MemoryImage& m_image;
    uint32_t m_index;
    std::vector<Context> m_contexts;
    std::priority_queue<Event, std::vector<Event>, std::greater<Event>> m_events;
    Cycle m_sched_free = 0;
    Cycle m_synced = 0;
    Cycle m_finish = 0;
    uint32_t m_active = 0;
    Cycle m_busy_since = 0, m_busy_cycles = 0;
    uint64_t m_rays = 0, m_steps = 0, m_spill_writes = 0, m_spill_reads = 0, m_rejected = 0, m_syncs = 0;
    bool m_treelet_mode = false;
    Cycle m_next_fill = 0;
    uint64_t m_parks = 0, m_takes = 0, m_idle_polls = 0;
};

}  // namespace rtsim
