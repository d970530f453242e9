#pragma once
// The structural alternatives traced beside a run's trace (`rtsim trace --alternatives`): the
// same scene, workload and rays under another structure, at
// TRACE_DIR/alternatives/<key>=<value>/trace.rtt (structure_alternative_dir). The verdict
// estimates each with the analytic level on the same sample of rays as the run's own design.
#include <memory>
#include <string>

#include "sim/config/config.h"
#include "sim/report/verdict.h"

namespace rtsim {

/// The alternatives beside `rtt`, opened for `config` (the run's config before resolution, so
/// the alternative's structure resolves it afresh). `rays` is the run's trace's: an alternative
/// with other rays is not the same workload and is refused.
AlternativeFactory alternative_traces(const std::string& rtt, const SimConfig& config, uint64_t rays);

}  // namespace rtsim
