#pragma once
// What a run writes besides the blocks' own stats is added by report blocks (docs/stats.md): the
// mailbox's, the short stack's, the reduced-precision walk's, the two-level structure's figures,
// energy and area, the roofline, the verdict. Each block registers itself from its own .cpp with
// the keys it writes and their declarations; the run loop (sim/harness/simulate.cpp) calls every
// registered block in order and checks their keys, naming none of them. A block reads the run's
// config, work and stats, never the run loop or a unit kind.
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "rtl_model/common/stats.h"
#include "sim/config/config.h"
#include "traces/common/work_counts.h"

namespace rtsim {

/// What a report block may read of a finished run (stats.json so far is its other input).
struct ReportInputs {
    const SimConfig& config;  ///< resolved
    const WorkTotals& work;   ///< every checked ray's work
    uint64_t rays = 0;        ///< rays the work is of
    std::string structure_kind;  ///< the trace's structure ("two_level", ...)
    /// The level's verdict (its estimates of what relaxing each knob buys), or null where the
    /// level has none or the run asked for none.
    std::function<nlohmann::json()> verdict;
};

struct ReportBlock {
    std::string name;  ///< what it reports, for messages
    int order = 0;     ///< blocks run in this order (one may read what an earlier one wrote)
    std::function<void(nlohmann::json& stats, const ReportInputs&)> add;
    /// The top-level keys it may write, each with its declaration (checked when present).
    std::vector<std::pair<std::string, const StatBlock& (*)()>> keys;
};

bool register_report_block(ReportBlock block);
/// The registered blocks, in order.
std::vector<const ReportBlock*> report_blocks();

#define RTSIM_REPORT_CONCAT2(a, b) a##b
#define RTSIM_REPORT_CONCAT(a, b) RTSIM_REPORT_CONCAT2(a, b)
/// Registers the ReportBlock `expr` from its owner's .cpp.
#define RTSIM_REGISTER_REPORT_BLOCK(expr)                                                        \
    namespace {                                                                                 \
    [[maybe_unused]] const bool RTSIM_REPORT_CONCAT(rtsim_report_block_registered_, __COUNTER__) = \
        ::rtsim::register_report_block(expr);                                                   \
    }

}  // namespace rtsim
