#include "sim/report/two_level_stats.h"
#include "sim/report/report_block.h"

namespace rtsim {

using nlohmann::json;

const StatBlock& two_level_stats() {
    static const StatBlock block{
        "two_level",
        {
            {"tlas_steps", "steps", "node steps in the top-level BVH (over the instances)"},
            {"blas_steps", "steps", "`steps - tlas_steps`: node and leaf steps inside the instances' BLASes"},
            {"tlas_box_tests", "tests", "box tests of the TLAS's node steps"},
            {"blas_box_tests", "tests", "`box_tests - tlas_box_tests`"},
            {"transforms", "ops", "instances entered (one ray transform each)"},
            {"tlas_step_fraction", "", "`tlas_steps / steps`; `null` without steps"},
            {"per_ray", "", "`{tlas_steps, blas_steps, tlas_box_tests, blas_box_tests, transforms}` per ray; `null` without rays"},
        }};
    return block;
}

void add_two_level_stats(json& stats, const WorkTotals& w, uint64_t rays) {
    const uint64_t steps = w[WorkField::steps], boxes = w[WorkField::box_tests];
    const uint64_t tlas = w[WorkField::tlas_steps], tlas_boxes = w[WorkField::tlas_box_tests];
    const uint64_t transforms = w[WorkField::transforms];
    auto per_ray = [&](uint64_t x) { return json(double(x) / double(rays)); };
    StatsWriter(two_level_stats(), stats["two_level"])
        .set("tlas_steps", tlas)
        .set("blas_steps", steps - tlas)
        .set("tlas_box_tests", tlas_boxes)
        .set("blas_box_tests", boxes - tlas_boxes)
        .set("transforms", transforms)
        .set("tlas_step_fraction", steps ? json(double(tlas) / double(steps)) : json(nullptr))
        .set("per_ray", rays ? json{{"tlas_steps", per_ray(tlas)},
                                    {"blas_steps", per_ray(steps - tlas)},
                                    {"tlas_box_tests", per_ray(tlas_boxes)},
                                    {"blas_box_tests", per_ray(boxes - tlas_boxes)},
                                    {"transforms", per_ray(transforms)}}
                             : json(nullptr))
        .done();
}

RTSIM_REGISTER_STAT_BLOCK(two_level_stats)

namespace {

ReportBlock two_level_report() {
    ReportBlock b;
    b.name = "two levels";
    b.order = 40;
    b.add = [](json& stats, const ReportInputs& in) {
        if (in.structure_kind == "two_level") add_two_level_stats(stats, in.work, in.rays);
    };
    b.keys = {{"two_level", two_level_stats}};
    return b;
}

}  // namespace

RTSIM_REGISTER_REPORT_BLOCK(two_level_report())

}  // namespace rtsim
