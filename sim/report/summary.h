#pragma once
// The headline numbers of a run (stats.json "summary"), derived from the blocks' stats, and the
// provenance record (version, git hash, command line, trace).
#include <cstdint>
#include <ctime>
#include <string>

#include <nlohmann/json.hpp>

#include "sim/config/config.h"
#include "sim/harness/hit_checker.h"

namespace rtsim {

nlohmann::json summarize(const SimConfig& config, uint64_t cycles, uint64_t rays, const nlohmann::json& model,
                         const HitChecker& checker, double wall_seconds);

/// started: the run's start as seconds since the epoch.
nlohmann::json provenance(const std::string& command_line, const std::string& trace, const nlohmann::json& manifest,
                          std::time_t started);

}  // namespace rtsim
