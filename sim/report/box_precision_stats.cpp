#include "sim/report/box_precision_stats.h"
#include "sim/report/report_block.h"

#include "sim/report/energy_area.h"

namespace rtsim {

using nlohmann::json;

const StatBlock& box_precision_stats() {
    static const StatBlock block{
        "box_precision",
        {
            {"bits", "bits", "`traversal.box_precision_bits`: explicit mantissa bits of the box tests (fp32: 23); with `traversal.quantized_boxes` 8 (the integer test's coordinates)"},
            {"arithmetic", "", "`reduced_fp` (`traversal.box_precision_bits`) or `quantized_int` (`traversal.quantized_boxes`: AQB8-style integer tests on the nodes' 8-bit grids, conservative by one grid cell)"},
            {"box_hits", "boxes", "boxes the reduced test entered that the fp32 walk rejected or culled at a pop: the roots of the extra walk"},
            {"steps", "steps", "node steps of the extra walk (each a node fetch, counted in the caches and units)"},
            {"box_tests", "tests", "box tests of those steps"},
            {"tri_tests", "tests", "triangle tests in the extra walk's leaves (each leaf a triangle fetch; never a hit)"},
            {"extra_steps_fraction", "", "`steps / summary work steps`: the extra walk over the fp32 walk's node steps; `null` without steps"},
            {"extra_box_tests_fraction", "", "`box_tests / box_tests of the fp32 walk`; `null` without box tests"},
            {"extra_tri_tests_fraction", "", "`tri_tests / tri_tests of the fp32 walk`; `null` without triangle tests"},
            {"box_test_pj", "pJ", "energy of one box test at this width (docs/energy_area.md, \"Reduced-precision box pipeline\")"},
            {"box_test_pj_fp32", "pJ", "the same test in fp32"},
            {"box_mm2", "mm^2", "area of all box pipelines at this width (also `area.mm2.box`)"},
            {"box_mm2_fp32", "mm^2", "the same pipelines in fp32"},
            {"per_ray", "", "`{box_hits, steps, box_tests, tri_tests}` per ray; `null` without rays"},
        }};
    return block;
}

void add_box_precision_stats(json& stats, const SimConfig& c, const WorkTotals& w, uint64_t rays) {
    const bool quantized = c.traversal.quantized_boxes;
    const uint32_t bits = quantized ? 8 : c.traversal.box_precision_bits;
    if (bits == 0) return;
    const uint64_t hits = w[WorkField::rp_box_hits], steps = w[WorkField::rp_steps];
    const uint64_t boxes = w[WorkField::rp_box_tests], tris = w[WorkField::rp_tri_tests];
    auto per_ray = [&](uint64_t x) { return rays ? json(double(x) / double(rays)) : json(nullptr); };
    auto fraction = [](uint64_t x, uint64_t of) { return of ? json(double(x) / double(of)) : json(nullptr); };
    const BoxPipelineCost reduced = box_pipeline_cost(c), fp32 = box_pipeline_cost(c, true);
    StatsWriter(box_precision_stats(), stats["box_precision"])
        .set("bits", bits)
        .set("arithmetic", quantized ? "quantized_int" : "reduced_fp")
        .set("box_hits", hits)
        .set("steps", steps)
        .set("box_tests", boxes)
        .set("tri_tests", tris)
        .set("extra_steps_fraction", fraction(steps, w[WorkField::steps]))
        .set("extra_box_tests_fraction", fraction(boxes, w[WorkField::box_tests]))
        .set("extra_tri_tests_fraction", fraction(tris, w[WorkField::tri_tests]))
        .set("box_test_pj", reduced.test_pj)
        .set("box_test_pj_fp32", fp32.test_pj)
        .set("box_mm2", reduced.mm2)
        .set("box_mm2_fp32", fp32.mm2)
        .set("per_ray", rays ? json{{"box_hits", per_ray(hits)},
                                    {"steps", per_ray(steps)},
                                    {"box_tests", per_ray(boxes)},
                                    {"tri_tests", per_ray(tris)}}
                             : json(nullptr))
        .done();
}

RTSIM_REGISTER_STAT_BLOCK(box_precision_stats)

namespace {

ReportBlock box_precision_report() {
    ReportBlock b;
    b.name = "reduced-precision or quantised boxes";
    b.order = 30;
    b.add = [](json& stats, const ReportInputs& in) { add_box_precision_stats(stats, in.config, in.work, in.rays); };
    b.keys = {{"box_precision", box_precision_stats}};
    return b;
}

}  // namespace

RTSIM_REGISTER_REPORT_BLOCK(box_precision_report())

}  // namespace rtsim
