#pragma once
// A short stack's figures in stats.json (docs/stats.md, "short_stack"; docs/accel.md, "Short
// stacks"): entries dropped, restarts and the re-traversal they cost, at every fidelity level
// (the counts come from the rays' work; their time is in the units' and caches' figures).
#include <cstdint>

#include <nlohmann/json.hpp>

#include "rtl_model/common/stats.h"
#include "sim/config/config.h"
#include "traces/common/work_counts.h"

namespace rtsim {

/// The block stats["short_stack"] (docs/stats.md).
const StatBlock& short_stack_stats();

/// Writes the section stats["short_stack"] when traversal.stack_overflow is restart_trail.
void add_short_stack_stats(nlohmann::json& stats, const SimConfig& config, const WorkTotals& work, uint64_t rays);

}  // namespace rtsim
