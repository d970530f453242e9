#include "sim/report/mailbox_stats.h"
#include "sim/report/report_block.h"

#include "traces/common/hw_triangle.h"

namespace rtsim {

using nlohmann::json;

const StatBlock& mailbox_stats() {
    static const StatBlock block{
        "mailbox",
        {
            {"entries", "ids", "`mailbox.entries`: primitive ids remembered per ray context"},
            {"sram_bytes", "B", "the mailboxes' SRAM: units x ray contexts x entries x 4 bytes"},
            {"lookups", "refs", "references looked up in a ray's mailbox before their triangle was fetched"},
            {"hits", "refs", "lookups that found the primitive: its triangle neither fetched nor tested"},
            {"misses", "refs", "`lookups - hits`"},
            {"hit_rate", "", "`hits / lookups`; `null` without lookups"},
            {"tri_tests", "tests", "triangle tests run (with the mailbox)"},
            {"tri_tests_without_mailbox", "tests", "`tri_tests + hits`: the tests the same rays run without one (what the trace records)"},
            {"tri_tests_saved_fraction", "", "`hits / tri_tests_without_mailbox`; `null` without tests"},
            {"triangle_fetch_bytes_saved", "B", "`hits x 48`: triangle bytes not fetched"},
            {"per_ray", "", "`{lookups, hits, tri_tests, tri_tests_without_mailbox}` per ray; `null` without rays"},
        }};
    return block;
}

void add_mailbox_stats(json& stats, const SimConfig& c, const WorkTotals& w, uint64_t rays) {
    const double n = double(rays);
    const uint64_t lookups = w[WorkField::mailbox_lookups], hits = w[WorkField::mailbox_hits];
    const uint64_t tests = w[WorkField::tri_tests];
    stats["summary"]["mailbox_hits_per_ray"] = c.mailbox.entries && rays ? json(double(hits) / n) : json(nullptr);
    if (!c.mailbox.entries) return;
    // Without the mailbox every hit would have been a triangle fetched and tested.
    const double without = double(tests + hits);
    auto per_ray = [&](double x) { return rays ? json(x / n) : json(nullptr); };
    StatsWriter(mailbox_stats(), stats["mailbox"])
        .set("entries", c.mailbox.entries)
        .set("sram_bytes", uint64_t(c.traversal.units) * c.traversal.contexts() * c.mailbox.entries *
                               MailboxConfig::kEntryBytes)
        .set("lookups", lookups)
        .set("hits", hits)
        .set("misses", lookups - hits)
        .set("hit_rate", lookups ? json(double(hits) / double(lookups)) : json(nullptr))
        .set("tri_tests", tests)
        .set("tri_tests_without_mailbox", uint64_t(without))
        .set("tri_tests_saved_fraction", without > 0 ? json(double(hits) / without) : json(nullptr))
        .set("triangle_fetch_bytes_saved", hits * sizeof(HwTriangle))
        .set("per_ray", json{{"lookups", per_ray(double(lookups))},
                             {"hits", per_ray(double(hits))},
                             {"tri_tests", per_ray(double(tests))},
                             {"tri_tests_without_mailbox", per_ray(without)}})
        .done();
}

RTSIM_REGISTER_STAT_BLOCK(mailbox_stats)

namespace {

ReportBlock mailbox_report() {
    ReportBlock b;
    b.name = "mailbox";
    b.order = 10;
    b.add = [](json& stats, const ReportInputs& in) { add_mailbox_stats(stats, in.config, in.work, in.rays); };
    b.keys = {{"mailbox", mailbox_stats}};
    return b;
}

}  // namespace

RTSIM_REGISTER_REPORT_BLOCK(mailbox_report())

}  // namespace rtsim
