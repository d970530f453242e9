#pragma once
// A reduced-precision box pipeline's figures in stats.json (docs/stats.md, "box_precision";
// docs/accel.md, "Reduced-precision box tests"): the extra walk its looser test causes, and the
// pipeline's energy and area beside fp32's, at every fidelity level (the counts come from the
// rays' work; their time is in the units' and caches' figures).
#include <cstdint>

#include <nlohmann/json.hpp>

#include "rtl_model/common/stats.h"
#include "sim/config/config.h"
#include "traces/common/work_counts.h"

namespace rtsim {

/// The block stats["box_precision"] (docs/stats.md).
const StatBlock& box_precision_stats();

/// Writes the section stats["box_precision"] when traversal.box_precision_bits is not 0.
void add_box_precision_stats(nlohmann::json& stats, const SimConfig& config, const WorkTotals& work, uint64_t rays);

}  // namespace rtsim
