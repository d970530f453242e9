#pragma once
// The headline numbers of a run (stats.json "summary"), derived from the blocks' stats, and the
// provenance record (version, git hash, command line, trace).
#include <cstdint>
#include <ctime>
#include <string>

#include <nlohmann/json.hpp>

#include "sim/config/config.h"

namespace rtsim {

/// What the run's hit check found, as the summary reports it.
struct CheckTotals {
    uint64_t hit_mismatches = 0;
    uint64_t work_mismatches = 0;
    double mean_latency_cycles = 0;  ///< the checked rays' mean latency (timed levels)
};

nlohmann::json summarize(const SimConfig& config, uint64_t cycles, uint64_t rays, const nlohmann::json& model,
                         const CheckTotals& check, double wall_seconds);

/// started: the run's start as seconds since the epoch.
nlohmann::json provenance(const std::string& command_line, const std::string& trace, const nlohmann::json& manifest,
                          std::time_t started);

}  // namespace rtsim
