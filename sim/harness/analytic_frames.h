#pragma once
// The analytic level over an animated trace (docs/fidelity.md, "Frames at the analytic level"):
// the closed form's traversal time shared out by each frame's rays, a refill of the machine at
// each barrier, and each frame's builds run on the build unit (rtl_model/build_unit/build_unit.h)
// against a closed-form memory: its lines through the L2 to DRAM at the DRAM's peak rate, reads
// waiting the unloaded miss latency, writes the L2's.
#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "rtl_model/build_unit/build_unit.h"
#include "sim/analytic/estimate.h"
#include "sim/config/config.h"
#include "traces/format/trace_format.h"
#include "traces/format/trace_reader.h"

namespace rtsim {

struct AnalyticFrames {
    uint64_t cycles = 0;            ///< every frame's build and traversal
    nlohmann::json frames;          ///< stats.json "frames" (frames.h, frame_stats())
    nlohmann::json build_unit;      ///< model.build_unit, null without builds
};

/// Each frame's planned-step work (node steps and tests, traces/common/work_counts.h) from the
/// trace's work records: what its traversal time is shared out by (a refitted tree that degrades
/// over the frames walks more steps per ray).
std::vector<double> frame_step_work(TraceReader& reader, const std::vector<FrameRecord>& frames);

/// `traversal_cycles`: the closed form's time for all the rays without barriers, shared out by
/// `step_work`; `mean_latency`: a ray's latency in it (the refill a barrier costs); `summary`:
/// its dram_bytes (shared out likewise), l1_hit_rate and l2_hit_rate (each frame's where `rates`
/// has one per frame: estimate.h's frame_hit_rates); `jobs`: each frame's builds (frame_builds.h).
AnalyticFrames estimate_frames(const SimConfig& config, const std::vector<FrameRecord>& frames,
                               const std::vector<double>& step_work, const nlohmann::json& manifest_frames,
                               const std::vector<std::vector<BuildJob>>& jobs, double traversal_cycles,
                               double mean_latency, const nlohmann::json& summary,
                               const std::vector<PredictedRates>& rates = {});

}  // namespace rtsim
