#pragma once
// The per-trace analysis of the analytic level (docs/fidelity.md, "The analytic level"): what
// the closed form needs from a trace, independent of cache sizes, pipelines, DRAM, MSHRs and
// latencies, so one analysis serves every configuration of a sweep that shares its key.
//
//   work:   the trace's per-ray work counts summed over every ray (the WORK section, one
//           streaming pass; no traversal)
//   sample: clusters of consecutive rays stepped with the structure's steppers in the machine's
//           interleaving (units x ray contexts, the dispatch policy): per data kind, the line
//           reads with their reuse distances in the unit's stream (its L1) and in the stream of
//           all units (the L2), jointly binned; the critical line of each step (for latency);
//           line writes; operation sizes per kind; steps per unit of work
//
// Quantities per unit of work come from the sample's measured rays and are scaled to the whole
// trace by its work counts (ratio estimators, Cochran 1977, ch. 6).
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rtl_model/traversal/unit_kind.h"
#include "sim/analytic/reuse.h"
#include "traces/accel/step_plan.h"
#include "traces/common/data_kind.h"

namespace rtsim {

/// A 2D histogram of accesses: (unit-stream bin, censored) x (global-stream bin, censored).
struct JointHistogram {
    std::map<uint32_t, double> cells;  ///< key: pack(...)
    static uint32_t pack(int unit_bin, bool unit_censored, int global_bin, bool global_censored) {
        return uint32_t(unit_bin) | uint32_t(unit_censored) << 8 | uint32_t(global_bin) << 9 |
               uint32_t(global_censored) << 17;
    }
    static void unpack(uint32_t key, int* ub, bool* uc, int* gb, bool* gc) {
        *ub = int(key & 0xFF), *uc = (key >> 8) & 1, *gb = int((key >> 9) & 0xFF), *gc = (key >> 17) & 1;
    }
    void add(uint32_t key, double n = 1) { cells[key] += n; }
    double total() const;
};

/// A merged-miss candidate's key (AnalyticProfile::merge_l1, merge_l2).
struct MergeKey {
    /// Reads closer than this (accesses in the stream) to a run's first read are in its run.
    static constexpr uint64_t kRunAccesses = 4096;
    /// Keys to octaves (each the bin at its middle): the wait varies little within one, and the
    /// histogram stays small.
    static uint64_t pack(uint32_t read_key, uint32_t head_key, int gap_bin) {
        return uint64_t(octaves(head_key)) | uint64_t(octave(gap_bin)) << 18 | uint64_t(octaves(read_key)) << 26;
    }
    static int octave(int bin) { return bin / DistanceBins::kSubBins * DistanceBins::kSubBins + DistanceBins::kSubBins / 2; }
    static uint32_t octaves(uint32_t key) {
        int ub, gb;
        bool uc, gc;
        JointHistogram::unpack(key, &ub, &uc, &gb, &gc);
        return JointHistogram::pack(octave(ub), uc, octave(gb), gc);
    }
    static void unpack(uint64_t k, uint32_t* read_key, uint32_t* head_key, int* gap_bin) {
        *head_key = uint32_t(k & 0x3FFFF), *gap_bin = int((k >> 18) & 0xFF), *read_key = uint32_t(k >> 26);
    }
};

/// A window of consecutive rounds of a whole-trace analysis (sample.h: every active context
/// takes one step per round, or waits the rounds its last step's slowest line takes when served
/// below the L1): what its steps asked for. The windows in order are the run's
/// phases: the fill (every ray at the top of the tree at once), the steady state and the drain
/// (fewer rays than contexts, the longest ray alone at the end), which a closed form over the
/// whole run's totals averages away (estimate.cpp, "phases").
struct PhaseWindow {
    double rounds = 0;        ///< rounds in the window
    double steps = 0;         ///< planned steps taken in them
    double contexts = 0;      ///< contexts busy in them, summed over the rounds (a step, or a ray's end and the next's start)
    // Keys to octaves (MergeKey::octaves): a window's shares of the run, not its absolute
    // figures, are what the estimate takes from them, and the analysis file stays small.
    JointHistogram reads;     ///< their line reads (every data kind)
    JointHistogram critical;  ///< each step's slowest line
};

/// One analysed frame of an animated trace (the cluster placed in it): the frame and its line
/// reads (every data kind, keys to octaves as PhaseWindow's), whose hit rates are the frame's.
struct FrameSample {
    uint32_t frame = 0;
    JointHistogram reads;
};

struct AnalyticProfile {
    nlohmann::json key;  ///< what the analysis depends on (analysis_cache.h)
    std::string accel_kind;        ///< the structure's kind (for the stats' why texts)
    std::vector<OpKind> op_kinds;  ///< operation kinds it issues (the pipelines it needs)

    // The whole trace (WORK section).
    uint64_t rays = 0;
    std::array<double, kWorkFieldCount> work{};  ///< sums over all rays, per field of work_counts.h
    double longest_ray_steps = 0;            ///< max over rays of its plan-step work (plan_step_work)
    double longest_ray_tests = 0;            ///< that ray's triangle tests

    // The sample's measured rays.
    double sample_rays = 0;
    bool whole_trace = false;  ///< the sample is the whole trace from its first ray: no history before it
    std::array<double, kWorkFieldCount> sample_work{};
    double sample_plan_steps = 0;           ///< steps the stepper planned (node and leaf steps)
    double plan_steps_per[2] = {0, 0};      ///< regression: plan steps = a plan-step work + b tri_tests
    std::vector<std::map<uint32_t, double>> op_sizes;  ///< per OpKind: operations by count
    std::array<JointHistogram, kDataKindCount> reads;   ///< line reads by reuse distances
    std::array<double, kDataKindCount> read_bytes{};    ///< bytes those reads asked for
    JointHistogram step_critical;   ///< per planned step: its slowest line (largest distances)
    JointHistogram ray_critical;    ///< per ray: its ray record's slowest line
    /// Step-critical lines read again while an earlier read of the line may still be missing
    /// (merged misses: the read waits for the fill, not the hit latency). Key (MergeKey): the
    /// read's joint key, the joint key of the read that began the line's run of close reads (the
    /// one that may have missed) and the bin of the accesses between them, in the unit's stream
    /// (the L1's MSHRs merge) and in the stream of all units (the L2's).
    std::map<uint64_t, double> merge_l1, merge_l2;
    std::array<double, kDataKindCount> writes{};      ///< line pieces written (write-through)
    std::array<double, kDataKindCount> write_bytes{};
    double spill_writes = 0, spill_reads = 0;        ///< stack entries
    // Reuse distance curves (events and censored by bin), all measured reads.
    std::vector<double> unit_events, unit_censored, global_events, global_censored;

    // Treelet scheduling (the sample stepped in treelet order, sample.h): the measured rays'
    // takes from the ray buffer, parks in other treelets' queues, and overflows of its SRAM.
    double treelet_takes = 0, treelet_parks = 0, treelet_overflows = 0;

    // Whole-trace analyses of contexts that run alone (one cluster from the first ray, no
    // treelet scheduling): the rounds in windows of equal length, at most kMaxPhaseWindows.
    static constexpr size_t kMaxPhaseWindows = 32;
    std::vector<PhaseWindow> phases;
    /// The machine the rounds ran on (the phases are its: a config of other counts has none).
    uint32_t phase_units = 0, phase_contexts = 0;
    /// Animated traces: each analysed frame's reads, in frame order (none for one frame).
    std::vector<FrameSample> frame_samples;

    // Lock-step unit kinds (SIMT warps, packets): the sample's rays stepped in the kind's groups,
    // functionally (UnitKind::group_profile): SIMD efficiency, coalescing, the groups' work.
    bool has_group = false;
    GroupProfile group;

    // Sampled rays checked against the reference (every stepped ray, warm-up included).
    nlohmann::json validation;
    nlohmann::json workload;  ///< rays per kind (stats.json "workload")
    uint64_t stepped_rays = 0;
    double analysis_seconds = 0;

    AnalyticProfile();
    nlohmann::json to_json() const;
    static AnalyticProfile from_json(const nlohmann::json& j);
    /// Sum of the plan-step fields of work sums (work or sample_work).
    static double plan_step_work(const std::array<double, kWorkFieldCount>& sums);
};

}  // namespace rtsim
