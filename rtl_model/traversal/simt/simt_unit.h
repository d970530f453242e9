#pragma once
// The SIMT traversal unit, traversal.model = "simt": the unit's ray contexts are the lanes of
// `ray_contexts / traversal.simt.lanes` warps, and a warp's lanes step in lock-step, as GPU ray tracing runs one
// ray per SIMD lane (Aila & Laine 2009; Vulkan-Sim's RT unit). Each lane drives its own stepper
// (its own stack) and costs its step with the step-demand function (../step_demand.h); the warp
// merges its lanes' demands:
//
//   warp step:  one operation kind for the warp (traversal.simt.policy: while-while or if-if, as
//               Aila & Laine define them); the lanes whose next step runs that kind step, the others
//               idle (counted: lane slots, idle_lane cycles)
//   fetches:    the stepping lanes' fetches coalesced per L1 line: one request per distinct line
//   operations: each kind's issues of all stepping lanes, to the kind's pipeline at its width
//               (a lane's tests never share an issue with another lane's: each issue tests one ray)
//   stack:      each lane's spills and fills, to its own spill slots
//
// Like the MIMD unit, a warp step is two scheduler phases (fetches, then operations) so requests
// to the private L1 and pipelines come in time order, and the unit runs ahead of SystemC time by
// at most quantum_cycles. A lane whose ray finished writes its hit at the warp's next step and
// takes a new ray then (traversal.simt.refill = lane, persistent threads) or once its whole warp
// has finished (warp); new rays' records are fetched in a warp step of their own (the lanes that
// fetch are its active lanes: refilling few lanes costs a mostly idle step, as on a GPU).
//
// Cooperative lanes (traversal.simt.cooperative; CoopRT: "Accelerating BVH Traversal for Ray
// Tracing via Cooperative Threads", ISCA 2025): a lane with no ray of its own (its ray finished
// and its warp has not retired, or dispatch has none) helps the warp's rays. CoopRT hands the
// helper an entry of a busy ray's traversal stack, whose subtree it walks with its own traversal
// hardware while the owner goes on. Here each ray's walk is stepped ahead when the ray starts, as
// a tree of steps (cooperation.h: a step depends on the step that descended into or pushed its
// node), and in each warp step the ray's lane and any idle lanes run its ready steps of the warp's
// operation kind, idle lanes going to the rays with the most ready steps; hits and every work
// count are the sequential walk's. A helper's fetches coalesce with the warp's, its tests issue to
// the pipelines like any lane's, its stack traffic goes to the ray's spill slots. With treelet
// queues (rays park by their next step's treelet, which a tree of ready steps has no one of) a
// helper instead runs the ray's next sequential step, if the ray's stack held an entry for it when
// the warp step began. What this leaves out: CoopRT's helpers walk with the best hit the ray had
// at the hand-over, so they may visit nodes the sequential order culls (our work is the sequential
// walk's, a lower bound on theirs), and the merge of the helpers' hits is priced, not timed.
#include <array>
#include <cstdint>
#include <vector>

#include "rtl_model/common/usage_series.h"
#include "rtl_model/traversal/scheduled_unit.h"
#include "rtl_model/traversal/simt/coalescer.h"
#include "rtl_model/traversal/simt/cooperation.h"
#include "rtl_model/traversal/simt/simt_config.h"
#include "rtl_model/traversal/treelet_prefetcher.h"
#include "rtl_model/traversal/unit_parts.h"

namespace rtsim {

class SimtUnit : public ScheduledUnit {
public:
    SC_HAS_PROCESS(SimtUnit);
    SimtUnit(sc_core::sc_module_name name, const UnitSetup& setup, uint32_t index);

    CycleAccount cycle_account(Cycle total_cycles) const override;
    nlohmann::json stats_json(Cycle total_cycles) const override;

    /// The kind's own stats (model.units.<unit> beside unit_stats()), bound to their counters.
    static const StatTable<SimtUnit>& kind_stats();

    /// The step class of a plan: its first operation's kind, or kOpKindCount for a step with none.
    static uint32_t step_class(const StepPlan& plan) { return warp_step_class(plan); }

private:
    static constexpr uint32_t kClasses = kOpKindCount + 1;
    static constexpr uint32_t kNoLane = 0xFFFFFFFFu;
    enum class Phase : uint8_t { step, ops };
    struct Lane {
        RayState ray;
        StepDemand demand;      ///< its step in the warp step in flight
        uint32_t treelet = kNoTreelet;  ///< prefetching without queues: the treelet its ray is in
        uint32_t helps = kNoLane;  ///< cooperative lanes: the lane whose ray it steps this warp step
        int spare = 0;             ///< cooperative lanes, treelet queues: stack entries not yet handed to a helper
        CooperativeWalk walk;      ///< cooperative lanes: its ray's recorded walk (m_walks)
        Cycle ready = 0;        ///< treelet scheduling: cycle its ray's state came from the ray buffer
        bool has_ray = false;
        bool stepping = false;  ///< active in the warp step in flight
        Cycle accounted = 0;
    };
    struct Warp {
        Phase phase = Phase::step;
        uint32_t treelet = kNoTreelet;  ///< treelet scheduling: the queue its rays come from
        uint32_t last_class = 0;  ///< the step class it ran last
    };

    void run();
    void fill_idle_warps(Cycle t);
    void advance(uint32_t w, Cycle t);
    void step(uint32_t w, Cycle t);
    void run_ops(uint32_t w, Cycle t);
    /// Finishes the lanes whose rays are done and refills lanes per simt_refill; true when rays
    /// were taken (the warp step then fetches their records).
    bool retire_and_refill(uint32_t w, Cycle t);
    void fetch_rays(uint32_t w, Cycle t);
    bool start_lane(uint32_t l, Cycle t, Cycle* fetch);
    /// Treelet scheduling: lane l of warp w takes a ray of the warp's treelet queue (a new
    /// treelet only when `may_switch`, its warp then empty); false when there is none.
    bool take_lane(uint32_t w, uint32_t l, Cycle t, bool may_switch, Cycle* fetch);
    /// Treelet scheduling: lanes whose next step lies in another treelet park their rays there.
    void park_leavers(uint32_t w, Cycle t);
    /// Prefetching without queues: lane l's next step entered another treelet.
    void note_treelet(uint32_t l, Cycle t);
    /// Runs the next step of lane `owner`'s ray into lane `into`'s demand (the same lane, or a
    /// helper), its reads to the coalescer.
    void step_ray(uint32_t owner, uint32_t into, uint32_t treelet);
    /// Cooperative lanes: the warp's lanes without a ray of their own step its rays (above).
    void lend_idle_lanes(uint32_t w, uint32_t cls, Cycle t);
    /// Cooperative lanes with recorded walks: runs a ready step of class `cls` of lane `owner`'s
    /// ray into lane `into`'s demand.
    void take_walk_step(uint32_t owner, uint32_t into, uint32_t cls, Cycle t);
    /// Lane l's ray is done (its walk all run, or its stepper done).
    bool ray_done(uint32_t l) const { return m_walks ? m_lanes[l].walk.done() : m_lanes[l].ray.stepper->plan().done; }
    /// The class lane l's ray steps next (its earliest ready step's, or its plan's).
    uint32_t lane_class(uint32_t l) const {
        return m_walks ? m_lanes[l].walk.next_class(kOpKindCount) : step_class(m_lanes[l].ray.stepper->plan());
    }
    /// The lane whose ray lane l steps this warp step (itself, or the lane it helps).
    uint32_t ray_lane(uint32_t l) const { return m_lanes[l].helps == kNoLane ? l : m_lanes[l].helps; }
    void fill_when_idle(Cycle t);
    void finish_lane(uint32_t l, Cycle t);
    /// The step class the warp runs next (simt_policy), or kClasses when no lane has a ray.
    uint32_t choose_class(uint32_t w) const;
    /// Counts a warp step of warp w (its lanes' `stepping` flags set) at cycle t.
    void count_warp_step(uint32_t w, Cycle t);
    nlohmann::json efficiency_by_kind() const;
    nlohmann::json efficiency_over_time() const;
    /// Lanes of warp w with a ray but not stepping (and, with warp refill, lanes waiting for the
    /// warp) spent up to `until` idle.
    void account_idle(uint32_t w, Cycle until);
    Cycle issue_reads(Cycle t, AccessInfo* slowest);
    bool warp_has_ray(uint32_t w) const;
    uint32_t first_lane(uint32_t w) const { return w * m_simt.lanes; }

    const SimtConfig& m_simt;
    const TreeletMap* m_treelets;  ///< treelet scheduling or prefetching; else null
    bool m_treelet_mode = false;   ///< rays come from and park in the ray buffer's treelet queues
    bool m_walks = false;          ///< cooperative lanes over recorded walks (no treelet queues)
    Cycle m_next_fill = 0;
    uint64_t m_parks = 0, m_takes = 0, m_idle_polls = 0;
    TreeletPrefetcher m_prefetcher;
    std::vector<Lane> m_lanes;
    std::vector<Warp> m_warps;
    LineCoalescer m_coalescer;
    Cycle m_fetch_at = 0;  ///< when the rays retire_and_refill() took may fetch their records
    uint64_t m_warp_steps = 0, m_lane_steps = 0, m_fetch_steps = 0;
    uint64_t m_helper_steps = 0, m_helped_warp_steps = 0;  ///< cooperative lanes
    std::vector<uint64_t> m_active_histogram;  ///< warp steps by active lanes (0 .. lanes)
    /// Per ray kind: lane-steps of lanes holding a ray of that kind, and those that stepped.
    std::array<uint64_t, kRayKindCount> m_kind_present{}, m_kind_active{};
    UsageSeries m_slot_use, m_active_use;  ///< lane slots and active lanes over time
};

}  // namespace rtsim
