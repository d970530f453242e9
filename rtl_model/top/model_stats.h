#pragma once
// The stats tree of the model (stats.json "model"), declared once: which blocks it holds and the
// model-wide blocks Top writes (cycle accounting, utilisation). Each block's own stats are
// declared by the block (unit_stats(), pipeline_stats(), cache_stats(), ...). The timed levels
// (Top::stats_json) and the analytic level build the same tree and check it with
// check_model_stats() before it is written, so the two cannot drift apart.
#include <string>

#include <nlohmann/json.hpp>

#include "rtl_model/common/stats.h"
#include "rtl_model/traversal/traversal_config.h"

namespace rtsim {

/// The keys of "model": one per block group.
const StatBlock& model_stats();
/// model.cycle_accounting: the units' cycle accounts summed.
const StatBlock& cycle_accounting_stats();
/// model.utilization: each shared resource's busy fraction, mean and over time.
const StatBlock& utilization_stats();

/// What stats.json "instantiated" says of ideal memory and of the traversal units ("8 units x 16
/// ray contexts"), at every level that builds or counts them.
inline constexpr const char* kIdealMemoryWhy = "ideal_memory: every access hits at L1 latency, no L2/DRAM";
std::string traversal_units_text(const TraversalConfig& traversal);

/// Checks a "model" object and every block in it against its declaration; throws rtsim::Error
/// naming the first undeclared or missing key.
/// `unit_kind`: traversal.model, whose stats block each unit's is checked against beside
/// unit_stats() (rtl_model/traversal/unit_stats.h).
void check_model_stats(const nlohmann::json& model, const std::string& unit_kind);

}  // namespace rtsim
