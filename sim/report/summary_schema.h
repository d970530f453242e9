#pragma once
// The keys of stats.json "summary", declared once: name, unit and meaning (a StatBlock like every
// block's, rtl_model/common/stats.h). summarize() and the sampling, energy and verdict steps
// write exactly these keys (check_summary, before stats.json is written), `rtsim-sim
// --dump-stats-schema` prints them with every block's, and docs/stats.md's tables are generated
// from them (scripts/gen_stats_doc.py; a test checks it).
#include <nlohmann/json.hpp>

#include "rtl_model/common/stats.h"

namespace rtsim {

/// Every summary key, in the order stats.json and the docs list them; `timed`: null at the
/// functional level; `optional`: present only in sampled runs.
const StatBlock& summary_stats();

/// The top level of stats.json and its "provenance", declared once.
const StatBlock& run_stats();
const StatBlock& provenance_stats();

/// Throws rtsim::Error naming the key if `summary` has a key the block does not declare, or
/// lacks one it declares (sampled-only keys are required only when `sampled`).
void check_summary(const nlohmann::json& summary, bool sampled);

}  // namespace rtsim
