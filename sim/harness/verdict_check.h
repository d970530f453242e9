#pragma once
// Checking the verdict by re-running (docs/stats.md, "verdict"; `rtsim-sim --check-verdict`):
// each of the verdict's top three knobs and its best co-limit pair, applied to the run's own
// resolved config, simulated at the run's level in its own rtsim-sim process (SystemC
// elaborates once per process), into RUN/check/<n>; the measured speed-up (rays/s relaxed over
// the run's) beside the estimate, so a user can trust or overrule the verdict in one command.
// The re-runs are sequential (they share the host with whatever else runs) and skip their own
// verdict.
#include <nlohmann/json.hpp>

#include "sim/harness/simulate.h"

namespace rtsim {

/// The re-runs of `verdict`'s top knobs and co-limits for the run `options` made (its
/// config.resolved.json is in options.out_dir), best measured first:
/// [{sets, estimated, measured, run, error}]. Throws rtsim::Error when rtsim-sim cannot be started.
nlohmann::json check_verdict(const SimOptions& options, const nlohmann::json& verdict, double rays_per_second);

}  // namespace rtsim
