#pragma once
// The analytic fidelity level: counts, a functional cache simulation and a closed-form
// (roofline) model of time. No SystemC time passes.
//
// Every ray is traced with the structure's stepper (the one the model's units drive), and every
// access its plans make (ray record, each step's fetches, stack spills and refills, hit record) goes through functional L1s (tags only, one per unit) and the shared L2 to
// DRAM. Rays go to ray contexts in trace order as contexts free up; the contexts of all units take
// one traversal step each in turn (unit 0 context 0, unit 1 context 0, ..., then context 1), so
// each L1 sees its unit's rays interleaved and the L2 sees all units interleaved, as in the timed
// model, but with no timing feedback on the order. The cycles are the largest of:
//
//   box / triangle / ...: issues x initiation_interval / pipelines      (pipeline throughput,
//                                                                       per operation kind used)
//   dram:      DRAM bytes / (channels x bytes_per_cycle)                 (bandwidth)
//   l2_banks:  L2 line accesses x bank_cycles / banks                    (L2 bank throughput)
//   l1_banks:  L1 line accesses x bank_cycles / (banks x units)          (L1 bank throughput)
//   scheduler: traversal steps x issue_cycles / units                    (decision logic)
//   latency:   sum over rays of the unloaded ray latency / (units x ray_contexts), and at least
//              the longest ray: latency hidden by the ray contexts (Little's law)
//
// The unloaded latency of a ray adds, per phase, the access latency of where its data was found
// (L1 hit, L2 hit, DRAM), the pipeline latency and the scheduler cycles. Each bound and the one
// that binds are reported under model.analytic (docs/stats.md).
#include <cstdint>

#include <nlohmann/json.hpp>

#include "rtl_model/common/interfaces.h"
#include "rtl_model/common/memory_map.h"
#include "rtl_model/dispatch/dispatch.h"
#include "sim/config/config.h"
#include "traces/accel/accel.h"

namespace rtsim {

struct AnalyticOutcome {
    Cycle cycles = 0;
    nlohmann::json model;         ///< same block names and keys as the SystemC model, plus "analytic"
    nlohmann::json instantiated;  ///< [{block, instantiated, why}]
};

/// Runs the analytic level over every ray of `rays`, reporting each finished ray to `sink`
/// (start 0, end = its unloaded latency).
AnalyticOutcome run_analytic(const SimConfig& config, const Accel& accel, const MemoryMap& map, RayStream& rays,
                             RaySinkIf& sink);

}  // namespace rtsim
