#pragma once
// Why is this design slow? (docs/stats.md, "verdict"). After a run, the verdict names the
// binding resource with its evidence and what relaxing it would buy:
//
//   1. candidates: at the timed levels, the resources behind the largest uses of the ray
//      contexts' cycles (cycle accounting: e.g. waiting for a free L1 MSHR), refined by
//      utilisation (DRAM data waits with the channels near peak are bandwidth, otherwise
//      latency), plus the saturated resources downstream of a full MSHR file (an L1 whose
//      misses queue at a saturated L2 MSHR file), plus the analytic level's binding bound.
//   2. relaxation: for each candidate, the config knob that relaxes it, doubled (l2.mshrs
//      32 -> 64, dram.channels 2 -> 4, ...), from one table (relaxation_for).
//   3. estimate: the analytic level run on a sample of the trace with the base config and with
//      each relaxed one; a speed-up is the ratio of their cycles. The binding resource is the
//      candidate whose relaxation buys the most (the largest cycle use when none buys 2%).
//      First order: the analytic level has its own error (docs/fidelity.md); an estimate of
//      direction and size, not a promise.
#include <cstdint>
#include <functional>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

#include "rtl_model/common/stats.h"
#include "rtl_model/common/memory_map.h"
#include "sim/config/config.h"
#include "traces/accel/accel.h"
#include "traces/format/trace_reader.h"

namespace rtsim {

/// A config change that relaxes one resource: "key" from "from" to "to".
struct Relaxation {
    std::string key;
    nlohmann::json from, to;
};

/// The knob that relaxes a resource (names of the analytic bounds: "l2_mshrs", "dram", "box",
/// "scheduler", "latency", ...), doubled; an empty key when no knob does.
Relaxation relaxation_for(const std::string& resource, const SimConfig& config);

struct VerdictContext {
    const SimConfig& config;
    const nlohmann::json& model;  ///< the run's model stats (cycle accounting, utilisation, ...)
    const Accel* accel;           ///< the structure, its memory map and the trace: the sample
    const MemoryMap* map;         ///< the analytic estimates run on (unless `estimate` is set)
    TraceReader* reader;
    uint64_t sample_rays = 8192;  ///< rays the analytic estimates run on (evenly spread blocks)
    /// When set, the analytic estimates (cycles, binding bound) come from it instead: the
    /// analytic level passes its own per-trace analysis, so it needs no second pass over rays.
    std::function<std::pair<double, std::string>(const SimConfig&)> estimate = {};
    std::string estimate_method = {};  ///< how `estimate` estimates, for the verdict's text
};

/// {binding, label, evidence, relax, estimate, analytic_binding, text}; null for the functional level.
nlohmann::json judge(const VerdictContext& context);

/// stats.json "verdict", declared once.
const StatBlock& verdict_stats();

}  // namespace rtsim
