#pragma once
// The roofline of a run (docs/stats.md, "roofline"): rays per second against DRAM bytes per ray,
// with the ceilings each resource puts on rays per second at this run's work per ray:
//   dram:      peak DRAM bandwidth / DRAM bytes per ray           (the slanted roof)
//   <kind>:    pipeline issue capacity / issues per ray, per operation kind (flat roofs)
//   scheduler: units x clock / (issue_cycles x scheduler steps per ray)
//   l1_mshrs, l2_mshrs: Little's law at each level, outstanding lines x line bytes / the
//              misses' mean MSHR hold time, over the level's miss bytes per ray
//   l2_banks:     L2 banks x line accesses per bank cycle x clock / L2 line accesses per ray
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
