#pragma once
// The keys of stats.json "summary", declared once: name, unit and meaning.
// summarize() and the sampling, energy and verdict steps write exactly these keys (a test checks
// both directions on real runs), `rtsim-sim --dump-stats-schema` prints them, and the summary
// table of docs/stats.md is generated from them (scripts/gen_stats_doc.py; a test checks it).
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace rtsim {

struct StatDecl {
    const char* key;
    const char* unit;     ///< "" when the value has no unit (a name, a flag)
    const char* meaning;  ///< one line, Markdown
    bool timed = false;   ///< null at the functional level (needs simulated time or caches)
    bool sampled_only = false;  ///< present only in sampled runs
};

/// Every summary key, in the order stats.json and the docs list them.
const std::vector<StatDecl>& summary_schema();

/// [{key, unit, meaning, timed, sampled_only}, ...] for --dump-stats-schema.
nlohmann::json summary_schema_json();

/// Throws rtsim::Error naming the key if `summary` has a key the schema does not declare, or
/// lacks one it declares (sampled-only keys are required only when `sampled`).
void check_summary(const nlohmann::json& summary, bool sampled);

}  // namespace rtsim
