#include "sim/report/short_stack_stats.h"
#include "sim/report/report_block.h"

namespace rtsim {

using nlohmann::json;

const StatBlock& short_stack_stats() {
    static const StatBlock block{
        "short_stack",
        {
            {"entries", "entries", "`traversal.stack_entries`: the short stack's entries per ray"},
            {"policy", "", "`traversal.stack_overflow`: `restart_trail`"},
            {"stack_drops", "entries", "oldest entries dropped by a push onto a full short stack (never written to memory)"},
            {"spill_bytes_avoided", "B", "`stack_drops x traversal.stack_entry_bytes`: what a spilling stack would have written for them"},
            {"restarts", "restarts", "restarts at the root: a pop found the short stack empty while entries had been dropped"},
            {"restart_steps", "steps", "node steps the restarts' re-descents revisited (each a node fetch, counted in the caches)"},
            {"restart_box_tests", "tests", "box tests of those revisits (box pipeline issues and energy)"},
            {"extra_steps_fraction", "", "`restart_steps / steps`: re-traversal over the full stack's node steps; `null` without steps"},
            {"extra_box_tests_fraction", "", "`restart_box_tests / box_tests`; `null` without box tests"},
            {"per_ray", "", "`{stack_drops, restarts, restart_steps, restart_box_tests}` per ray; `null` without rays"},
        }};
    return block;
}

void add_short_stack_stats(json& stats, const SimConfig& c, const WorkTotals& w, uint64_t rays) {
    if (c.traversal.stack_overflow == StackOverflow::spill) return;
    const uint64_t drops = w[WorkField::stack_drops], restarts = w[WorkField::restarts];
    const uint64_t steps = w[WorkField::restart_steps], boxes = w[WorkField::restart_box_tests];
    const uint64_t ref_steps = w[WorkField::steps], ref_boxes = w[WorkField::box_tests];
    auto per_ray = [&](uint64_t x) { return rays ? json(double(x) / double(rays)) : json(nullptr); };
    StatsWriter(short_stack_stats(), stats["short_stack"])
        .set("entries", c.traversal.stack_entries)
        .set("policy", kStackOverflowChoices.name(c.traversal.stack_overflow))
        .set("stack_drops", drops)
        .set("spill_bytes_avoided", drops * c.traversal.stack_entry_bytes)
        .set("restarts", restarts)
        .set("restart_steps", steps)
        .set("restart_box_tests", boxes)
        .set("extra_steps_fraction", ref_steps ? json(double(steps) / double(ref_steps)) : json(nullptr))
        .set("extra_box_tests_fraction", ref_boxes ? json(double(boxes) / double(ref_boxes)) : json(nullptr))
        .set("per_ray", rays ? json{{"stack_drops", per_ray(drops)},
                                    {"restarts", per_ray(restarts)},
                                    {"restart_steps", per_ray(steps)},
                                    {"restart_box_tests", per_ray(boxes)}}
                             : json(nullptr))
        .done();
}

RTSIM_REGISTER_STAT_BLOCK(short_stack_stats)

namespace {

ReportBlock short_stack_report() {
    ReportBlock b;
    b.name = "short stack";
    b.order = 20;
    b.add = [](json& stats, const ReportInputs& in) { add_short_stack_stats(stats, in.config, in.work, in.rays); };
    b.keys = {{"short_stack", short_stack_stats}};
    return b;
}

}  // namespace

RTSIM_REGISTER_REPORT_BLOCK(short_stack_report())

}  // namespace rtsim
