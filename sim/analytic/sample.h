#pragma once
// The sampled part of the analytic level's per-trace analysis (profile.h): clusters of
// consecutive rays stepped with the structure's steppers (the ones the model's units drive, so
// the plans' fetches are the model's) in the machine's interleaving: rays go to units by the
// model's dispatch policy (RayDealer), each unit runs ray_contexts rays, and the contexts of all
// units take one step each in turn (unit 0 context 0, unit 1 context 0, ..., then context 1).
// Each line read is recorded with its reuse distance in its unit's stream (the unit's L1 sees
// it) and in the stream of all units (the L2). Clusters are contiguous in trace order, so the
// local reuse (neighbouring pixels) is the full run's; each starts with warm-up rays whose
// accesses only build history (as SMARTS warms caches, Wunderlich et al. 2003).
//
// With treelet scheduling (treelets.enabled) the rays are stepped in the order the ray buffer
// would run them, functionally: rays enter the queue of their first step's treelet while fewer
// than the admission limit are in the machine (their record read in the shared stream), each
// unit's contexts take rays from the queue of the unit's current treelet, a ray whose next step
// lies in another treelet is parked in that treelet's queue (the context takes the next), and a
// unit whose queue runs dry picks another by treelets.policy. The reuse distances are then those
// of the treelet order; takes, parks and overflows (queued rays beyond the SRAM) are counted.
#include <cstdint>
#include <deque>
#include <memory>
#include <set>
#include <vector>

#include "rtl_model/common/interfaces.h"
#include "rtl_model/common/memory_map.h"
#include "rtl_model/dispatch/dispatch.h"
#include "rtl_model/traversal/step_demand.h"
#include "rtl_model/traversal/unit_parts.h"
#include "sim/analytic/key_counts.h"
#include "sim/analytic/profile.h"
#include "sim/analytic/reuse.h"
#include "sim/config/config.h"
#include "traces/accel/accel.h"

namespace rtsim {

class SampleProfiler {
public:
    SampleProfiler(const SimConfig& config, const Accel& accel, const MemoryMap& map, const StepOptions& step,
                   AnalyticProfile& profile);
    /// Steps every ray of `stream` (one cluster, fresh history); rays with trace index in
    /// [measure_first, measure_end) are measured. Every stepped ray goes to `sink` (the checker).
    void run_cluster(RayStream& stream, uint64_t measure_first, uint64_t measure_end, RaySinkIf& sink);
    /// Animated traces: the measured reads of the clusters run from now on are frame `frame`'s
    /// (profile.h, FrameSample).
    void begin_frame_sample(uint32_t frame);
    /// Fits steps per unit of work; call once after the clusters.
    void finish();

private:
    struct Ray {
        std::unique_ptr<Stepper> stepper;
        uint64_t id = 0;
        StackSplit stack;
        uint32_t plan_steps = 0;
        bool measured = false;
    };
    struct Context : Ray {
        bool active = false;
        uint32_t wait = 0;  ///< rounds it still waits for its last step's slowest line
        uint32_t treelet = 0;  ///< treelet scheduling: the treelet its ray is in
    };
    /// A line read's reuse key (JointHistogram::pack) and its ordering weight for "slowest".
    struct Access {
        uint32_t key = 0;
        uint64_t rank = 0;
        bool merge_l1 = false, merge_l2 = false;  ///< within a line's run of close reads (MergeKey)
        uint64_t merge_l1_key = 0, merge_l2_key = 0;
    };
    bool start_ray(RayDealer& dealer, uint32_t unit, uint32_t slot, RaySinkIf& sink);
    /// Treelet scheduling: the cluster stepped in treelet order (the header's comment).
    void run_treelets(RayDealer& dealer, RaySinkIf& sink);
    void admit(RayDealer& dealer);
    bool take_ray(uint32_t unit, uint32_t slot);
    void park(Ray&& ray, uint32_t treelet);
    int64_t pick() const;
    void step(RayDealer& dealer, uint32_t unit, uint32_t slot, RaySinkIf& sink);
    Access read(uint32_t unit, uint64_t addr, uint32_t bytes, DataKind kind, bool measured);
    Access read_line(uint32_t unit, uint64_t line, DataKind kind, bool measured);
    void write(uint64_t addr, uint32_t bytes, DataKind kind, bool measured);
    void stack_traffic(uint32_t unit, uint32_t slot, const StepDemand& d, bool measured);
    void finish_ray(Context& ctx, uint32_t unit, uint32_t slot, RaySinkIf& sink);
    /// Whole-trace analyses: the round just run into the current phase window (profile.h),
    /// halving the windows' count by merging neighbours when it reaches the maximum.
    void end_round();
    /// Speed only: the host data of context `index`'s next step and its first line's reuse slots.
    void prefetch_ahead(size_t index) const;

    const SimConfig& m_c;
    const StepCosts m_costs;
    const MemoryMap& m_map;
    AnalyticProfile& m_p;
    std::vector<Context> m_contexts;  ///< unit-major
    /// Per context, what its next step touches on the host, noted when it is planned (hot then)
    /// and prefetched a few steps before it runs: the round's other units x ray_contexts - 1
    /// steps ran since, evicting it.
    std::vector<HostAhead> m_ahead;
    uint32_t m_units, m_slots, m_shift;
    uint64_t m_measure_first = 0, m_measure_end = 0;
    LastUse m_unit_last, m_global_last;
    uint64_t m_global_pos = 0;
    std::vector<uint64_t> m_unit_pos;
    // The profile's histograms as counted (finish() moves them into the profile).
    std::vector<KeyCounts> m_reads, m_op_sizes;  ///< per DataKind, per OpKind
    KeyCounts m_step_critical, m_ray_critical;
    // Phase windows as counted (whole-trace analyses only; finish() moves them into the profile).
    struct PhaseCounts {
        double rounds = 0, steps = 0, contexts = 0;
        KeyCounts reads, critical;
    };
    std::vector<PhaseCounts> m_phases;
    double m_window_rounds = 1;  ///< rounds per window
    bool m_record_phases = false;
    std::vector<std::pair<uint32_t, KeyCounts>> m_frame_reads;  ///< begin_frame_sample's, in order
    uint32_t m_clusters_run = 0;
    // Treelet scheduling only (treelets.enabled).
    std::unique_ptr<LocalityPartition> m_partition;
    std::vector<std::deque<Ray>> m_queues;
    /// The non-empty queues by size (largest first, then lowest index) and by index, kept with
    /// every park and take so a pick does not scan every treelet (a grid's cells are thousands).
    std::set<std::pair<int64_t, uint32_t>> m_by_size;
    std::set<uint32_t> m_nonempty;
    /// Queue t's size changes by `delta` (its entries in the indexes follow).
    void resize_queue_index(uint32_t t, int64_t delta);
    std::vector<int64_t> m_unit_treelet;
    std::vector<std::unique_ptr<Stepper>> m_free;  ///< steppers of finished rays, reused
    const Accel* m_accel = nullptr;
    StepOptions m_step;
    /// Merged-miss candidates are counted for contexts that run alone (a lock-step kind's
    /// group step waits for its slowest read anyway: estimate.cpp's max_latency).
    bool m_merges;
    uint64_t m_in_machine = 0, m_waiting = 0, m_admit_limit = 0, m_capacity = 0;
    uint32_t m_round_robin = 0;
    double m_fit[5] = {};  ///< sums x1x1, x1x2, x2x2, x1y, x2y of the steps regression
};

}  // namespace rtsim
