#pragma once
// The roofline of a run (docs/stats.md, "roofline"): rays per second against DRAM bytes per ray,
// with the ceilings each resource puts on rays per second at this run's work per ray:
//   dram:      peak DRAM bandwidth / DRAM bytes per ray           (the slanted roof)
//   <kind>:    pipeline issue capacity / issues per ray, per operation kind (flat roofs)
//   scheduler: units x clock / (issue_cycles x scheduler steps per ray)
// A run sits under all of them; the lowest ceiling is the roofline's bound for its work.
#include <nlohmann/json.hpp>

#include "rtl_model/common/stats.h"
#include "sim/config/config.h"

namespace rtsim {

/// {dram_bytes_per_ray, rays_per_second, ceilings: {name: rays/s}, bound, bound_rays_per_second};
/// null when the level has no time (functional).
nlohmann::json roofline_json(const SimConfig& config, const nlohmann::json& summary, const nlohmann::json& model);

/// stats.json "roofline", declared once.
const StatBlock& roofline_stats();

}  // namespace rtsim
