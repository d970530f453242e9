#pragma once
// Every stats block a run can write, declared by its producer and registered from its .cpp
// (rtl_model/common/stats.h): what `rtsim-sim --dump-stats-schema` prints and docs/stats.md's
// tables are generated from; and the check of a run's whole stats.json against them.
#include <vector>

#include <nlohmann/json.hpp>

#include "rtl_model/common/stats.h"

namespace rtsim {

/// [{path, stats: [{key, unit, meaning, timed, optional}]}, ...]
nlohmann::json stats_schema_json();
/// Checks a run's whole stats.json against the declarations before it is written (the model
/// tree is checked where it is built: check_model_stats); throws naming the first undeclared or
/// missing key.
void check_run_stats(const nlohmann::json& stats, bool sampled);

}  // namespace rtsim
