#include "sim/harness/mailbox_stats.h"

#include "traces/common/hw_triangle.h"

namespace rtsim {

using nlohmann::json;

void add_mailbox_stats(json& stats, const SimConfig& c, const WorkTotals& w, uint64_t rays) {
    const double n = double(rays);
    stats["summary"]["mailbox_hits_per_ray"] = c.mailbox.entries && rays ? json(double(w.mailbox_hits) / n) : json(nullptr);
    if (!c.mailbox.entries) return;
    // Without the mailbox every hit would have been a triangle fetched and tested.
    const double without = double(w.tri_tests + w.mailbox_hits);
    auto per_ray = [&](double x) { return rays ? json(x / n) : json(nullptr); };
    stats["mailbox"] = {
        {"entries", c.mailbox.entries},
        {"sram_bytes", uint64_t(c.traversal.units) * c.traversal.ray_contexts * c.mailbox.entries *
                           MailboxConfig::kEntryBytes},
        {"lookups", w.mailbox_lookups},
        {"hits", w.mailbox_hits},
        {"misses", w.mailbox_lookups - w.mailbox_hits},
        {"hit_rate", w.mailbox_lookups ? json(double(w.mailbox_hits) / double(w.mailbox_lookups)) : json(nullptr)},
        {"tri_tests", w.tri_tests},
        {"tri_tests_without_mailbox", uint64_t(without)},
        {"tri_tests_saved_fraction", without > 0 ? json(double(w.mailbox_hits) / without) : json(nullptr)},
        {"triangle_fetch_bytes_saved", w.mailbox_hits * sizeof(HwTriangle)},
        {"per_ray", {{"lookups", per_ray(double(w.mailbox_lookups))},
                     {"hits", per_ray(double(w.mailbox_hits))},
                     {"tri_tests", per_ray(double(w.tri_tests))},
                     {"tri_tests_without_mailbox", per_ray(without)}}},
    };
}

}  // namespace rtsim
