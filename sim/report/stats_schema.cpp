#include "sim/report/stats_schema.h"

#include "sim/report/report_block.h"
#include "sim/report/summary_schema.h"
#include "traces/common/error.h"

namespace rtsim {

void check_run_stats(const nlohmann::json& stats, bool sampled) {
    run_stats().check(stats);
    check_summary(stats.at("summary"), sampled);
    require(sampled == stats.contains("sampling"), "stats: 'sampling' is written exactly in sampled runs");
    if (sampled) registered_stat_block("sampling").check(stats.at("sampling"));
    for (const ReportBlock* b : report_blocks())
        for (const auto& [key, block] : b->keys)
            if (stats.contains(key) && !stats.at(key).is_null()) block().check(stats.at(key));
    if (stats.contains("frames"))
        for (const nlohmann::json& f : stats.at("frames")) registered_stat_block("frames[]").check(f);
    for (const char* key : {"validation", "latency", "workload", "provenance"})
        registered_stat_block(key).check(stats.at(key));
}

nlohmann::json stats_schema_json() {
    nlohmann::json out = nlohmann::json::array();
    for (const StatBlock* b : registered_stat_blocks()) out.push_back(b->schema_json());
    return out;
}

}  // namespace rtsim
