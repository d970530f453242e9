#pragma once
// A two-level walk's split in stats.json (docs/stats.md, "two_level"; docs/accel.md, "Two-level
// structures"): the TLAS's steps and box tests against the BLASes', and the transforms between.
#include <cstdint>

#include <nlohmann/json.hpp>

#include "rtl_model/common/stats.h"
#include "traces/common/work_counts.h"

namespace rtsim {

/// The block stats["two_level"] (docs/stats.md).
const StatBlock& two_level_stats();

/// Writes the section stats["two_level"] from the steppers' counts (levels that step every ray:
/// not the statistical analytic level, whose work comes from the trace's records).
void add_two_level_stats(nlohmann::json& stats, const WorkTotals& work, uint64_t rays);

}  // namespace rtsim
