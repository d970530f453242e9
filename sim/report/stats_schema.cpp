#include "sim/report/stats_schema.h"

#include "rtl_model/dispatch/dispatch.h"
#include "rtl_model/isect/pipeline.h"
#include "rtl_model/mem/mem_stats.h"
#include "rtl_model/ray_buffer/ray_buffer.h"
#include "rtl_model/top/model_stats.h"
#include "rtl_model/traversal/traversal_unit.h"
#include "sim/analytic/closed_form.h"
#include "sim/harness/frames.h"
#include "sim/harness/hit_checker.h"
#include "sim/harness/run_files.h"
#include "sim/report/energy_area.h"
#include "sim/report/mailbox_stats.h"
#include "sim/report/roofline.h"
#include "sim/report/short_stack_stats.h"
#include "sim/report/box_precision_stats.h"
#include "sim/report/two_level_stats.h"
#include "sim/report/summary_schema.h"
#include "sim/report/verdict.h"
#include "sim/sampling/sampling.h"
#include "traces/common/error.h"

namespace rtsim {

std::vector<const StatBlock*> stats_blocks() {
    return {&run_stats(),        &summary_stats(),      &sampling_stats(),   &energy_stats(),
            &area_stats(),       &verdict_stats(),      &roofline_stats(),   &frame_stats(),
            &validation_stats(), &latency_stats(),      &workload_stats(),   &model_stats(),
            &dispatch_stats(),   &ray_buffer_stats(),   &unit_stats(),       &pipeline_stats(),
            &cache_stats(),      &dram_stats(),         &cycle_accounting_stats(), &utilization_stats(),
            &analytic_stats(),   &ideal_memory_stats(), &provenance_stats(), &mailbox_stats(),
            &short_stack_stats(), &two_level_stats(), &box_precision_stats()};
}

void check_run_stats(const nlohmann::json& stats, bool sampled) {
    run_stats().check(stats);
    check_summary(stats.at("summary"), sampled);
    require(sampled == stats.contains("sampling"), "stats: 'sampling' is written exactly in sampled runs");
    if (sampled) sampling_stats().check(stats.at("sampling"));
    energy_stats().check(stats.at("energy"));
    area_stats().check(stats.at("area"));
    if (!stats.at("verdict").is_null()) verdict_stats().check(stats.at("verdict"));
    if (!stats.at("roofline").is_null()) roofline_stats().check(stats.at("roofline"));
    if (stats.contains("frames"))
        for (const nlohmann::json& f : stats.at("frames")) frame_stats().check(f);
    if (stats.contains("mailbox")) mailbox_stats().check(stats.at("mailbox"));
    if (stats.contains("short_stack")) short_stack_stats().check(stats.at("short_stack"));
    if (stats.contains("two_level")) two_level_stats().check(stats.at("two_level"));
    if (stats.contains("box_precision")) box_precision_stats().check(stats.at("box_precision"));
    validation_stats().check(stats.at("validation"));
    latency_stats().check(stats.at("latency"));
    workload_stats().check(stats.at("workload"));
    provenance_stats().check(stats.at("provenance"));
}

nlohmann::json stats_schema_json() {
    nlohmann::json out = nlohmann::json::array();
    for (const StatBlock* b : stats_blocks()) out.push_back(b->schema_json());
    return out;
}

}  // namespace rtsim
