#pragma once
// The mailboxes' figures in stats.json (docs/stats.md, "mailbox"; docs/accel.md, "Mailboxes"):
// lookups, hits and misses, the triangle tests and fetches they saved, at every fidelity level
// (the counts come from the rays' work, not from time).
#include <cstdint>

#include <nlohmann/json.hpp>

#include "rtl_model/common/stats.h"
#include "sim/config/config.h"
#include "traces/common/work_counts.h"

namespace rtsim {

/// The block stats["mailbox"] (docs/stats.md).
const StatBlock& mailbox_stats();

/// Writes summary.mailbox_hits_per_ray (null without a mailbox) and, when mailbox.entries > 0,
/// the section stats["mailbox"].
void add_mailbox_stats(nlohmann::json& stats, const SimConfig& config, const WorkTotals& work, uint64_t rays);

}  // namespace rtsim
