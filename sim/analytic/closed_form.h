#pragma once
// The analytic level's closed form of time (docs/fidelity.md, "The analytic level"): a roofline
// of the machine's resources and mean value analysis of the ray contexts as a closed queueing
// network, from demands alone (counts, bytes, hold times, unloaded latencies). Both the exact
// functional-cache model and the statistical one feed it, and so does the verdict through them.
//
// The roofline's bounds, in cycles (the largest binds):
//   box / triangle / ...: issues x initiation_interval / pipelines      (per operation kind used)
//   dram:      DRAM bytes / (channels x bytes_per_cycle)
//   l2_banks:  L2 line accesses x bank_cycles / banks
//   l1_banks:  L1 line accesses x bank_cycles / (banks x units)
//   l1_mshrs / l2_mshrs: miss hold time / MSHRs (Little's law: each miss holds one for its
//              unloaded miss latency)
//   scheduler: scheduler steps x issue_cycles / units
//   latency:   sum of the rays' unloaded latencies / (units x ray_contexts), at least the
//              longest ray (latency hidden by the ray contexts, Little's law)
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rtl_model/common/stats.h"
#include "sim/config/config.h"
#include "traces/accel/step_plan.h"

namespace rtsim {

/// What the closed form needs: whole-run totals.
struct AnalyticDemands {
    double rays = 0;
    double issues[kOpKindCount] = {};  ///< pipeline issues per operation kind
    double scheduler_steps = 0;        ///< one per ray (its fetch) and two per planned step
    double l1_accesses = 0, l2_accesses = 0, dram_bytes = 0;  ///< line accesses (reads + writes)
    double l1_hold = 0, l2_hold = 0;   ///< cycles misses hold an L1 / L2 MSHR, summed
    double latency_sum = 0;            ///< sum of the rays' unloaded latencies
    double latency_max = 0;            ///< the longest ray's
    /// What circulates through the machine in the mean value analysis: each unit's ray contexts,
    /// each visiting once per ray (0, 0: the config's contexts and d.rays); a lock-step kind's
    /// groups, each visiting once per group step (its rays step, wait and issue together).
    double customers = 0, visits = 0;
    /// A lock-step kind's rays held per group (its occupied lanes): the rays' residence over
    /// them is a group visit's delay (0: contexts / customers).
    double group_rays = 0;
    /// Treelet scheduling: bytes through the ray buffer's SRAM port, and the takes' latency.
    double ray_buffer_bytes = 0, latency_sum_extra = 0;
    /// Mean wait per planned step for fills already in flight (merged misses), in latency_sum.
    double merge_wait = 0;
    /// Contexts that run alone: how many one fill releases at once (its read's and the merged
    /// ones'), the rays a customer carries (customers, visits and group_rays say so); 1: none.
    double convoy = 1;
};

/// One window of a run's phases (profile.h's PhaseWindow) as shares of the whole run's demands:
/// what drives each resource in the window over its whole-run total, the window's unloaded
/// latency summed over its steps, and the customers active in it per unit (its steps over its
/// rounds and the units: contexts, or a lock-step kind's groups).
struct PhaseShare {
    double steps = 0;     ///< scheduler, rays (a lock-step kind's visits: its group steps)
    double work = 0;      ///< pipelines' issues: the steps, or a lock-step kind's active lanes
    double l1_misses = 0; ///< L1 MSHRs, L2 banks
    double l2_misses = 0; ///< DRAM, L2 MSHRs
    double reads = 0;     ///< L1 banks
    double latency_sum = 0;
    double population = 0;
};

struct ClosedForm {
    nlohmann::json bounds;  ///< {name: cycles}
    std::string binding;    ///< the largest bound
    double roofline = 0;    ///< its cycles
    double queueing = 0;    ///< the MVA estimate
    double cycles = 0;      ///< max(roofline, queueing), rounded up (times phase_factor)
    /// A whole-trace analysis's phases: the windows' cycles summed over max(roofline, queueing)
    /// (1: no phases known, or the sum is below); `cycles` carries it.
    double phase_factor = 1;
    /// max(roofline, queueing), rounded up, without the phases: what estimates are compared on
    /// when one of them has no phases (another structure, treelets, a lock-step kind).
    double steady_cycles = 0;
    double dram_bytes = 0;  ///< the DRAM bytes behind it (the demands'): what a knob's traffic costs in energy
};

/// The roofline and the MVA estimate of a run with these demands (ideal_memory: no cache or
/// DRAM bounds); with `phases`, each window is also priced as a run of its own (its share of the
/// demands at its population) and the run is at least their sum.
ClosedForm closed_form(const SimConfig& config, const std::vector<OpKind>& ops, const AnalyticDemands& d,
                       const std::vector<PhaseShare>& phases = {});

/// The stats of model.analytic, declared once.
const StatBlock& analytic_stats();
/// Checks a model tree the analytic level wrote against the declarations (the model's blocks
/// and model.analytic), as the timed levels' is checked (check_model_stats).
void check_analytic_model(const nlohmann::json& model, const std::string& unit_kind);

/// The closed form's keys of model.analytic (docs/stats.md).
nlohmann::json closed_form_json(const ClosedForm& f, const AnalyticDemands& d);

/// The pipeline blocks of stats.json (model.box, model.triangle, ...) from per-unit issues and
/// tests, with utilisation over `cycles`.
nlohmann::json pipelines_json(const SimConfig& config, const std::vector<OpKind>& ops,
                              const std::vector<std::vector<double>>& unit_issues,
                              const std::vector<std::vector<double>>& unit_tests, double cycles);

/// The instantiated blocks of an analytic run.
nlohmann::json analytic_instantiated(const SimConfig& config, const std::string& accel_kind,
                                     const std::vector<OpKind>& ops, const std::string& memory_why);

}  // namespace rtsim
