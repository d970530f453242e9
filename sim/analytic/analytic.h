#pragma once
// The analytic fidelity level (docs/fidelity.md, "The analytic level"): first-order answers from
// a per-trace analysis and a closed form, no SystemC time, no traversal of every ray.
//
//   1. analysis (once per trace and key, cached beside the trace: analysis_cache.h): the trace's
//      work counts summed over every ray (one streaming pass over WORK), and clusters of rays
//      stepped in the machine's interleaving, recording reuse distances per data kind in each
//      unit's stream and in all units' stream (sample.h, profile.h);
//   2. per configuration: hit rates of the L1s and the L2 for their sizes and ways from the
//      reuse distances (StatStack, reuse.h), traffic and unloaded latencies scaled by
//      the work counts (estimate.h), then the roofline and mean value analysis
//      (closed_form.h).
//
// Hit checking at this level: every ray the analysis steps (its sample, warm-up included) is
// checked against the reference hit and work bit for bit; every other ray's work record is read
// (its chunk's CRC verified) and used as the work the model counts. The functional level checks
// every ray in full.
#include <cstdint>
#include <functional>
#include <vector>

#include <nlohmann/json.hpp>

#include "rtl_model/common/interfaces.h"
#include "rtl_model/common/memory_map.h"
#include "rtl_model/dispatch/dispatch.h"
#include "sim/config/config.h"
#include "sim/analytic/profile.h"
#include "traces/accel/accel.h"
#include "traces/format/trace_reader.h"

namespace rtsim {

struct AnalyticOutcome {
    Cycle cycles = 0;
    nlohmann::json model;         ///< same block names and keys as the SystemC model, plus "analytic"
    nlohmann::json instantiated;  ///< [{block, instantiated, why}]
};

/// The analytic level over the rays of `rays` (all of them stepped and measured: the stream is
/// its own sample, e.g. the verdict's 8192 rays), each finished ray reported to `sink` (start
/// and end 0). The analysis of a stream is kept in memory for the process, so evaluating several
/// configurations with the same key on the same rays steps them once.
AnalyticOutcome run_analytic(const SimConfig& config, const Accel& accel, const MemoryMap& map,
                             const StepOptions& step, RayStream& rays, RaySinkIf& sink);

/// The analysis run_analytic evaluates: the stream stepped once per process and key (later calls
/// with the same rays and key return the kept analysis, replaying the results to `sink`). The
/// reference stays valid until the next call (a handful of analyses are kept).
const AnalyticProfile& analyze_stream(const SimConfig& config, const Accel& accel, const MemoryMap& map,
                                      const StepOptions& step, RayStream& rays, RaySinkIf& sink);

/// The exact variant: every ray stepped, every access through functional
/// caches on unloaded clocks (exact.cpp); for tests and comparisons.
AnalyticOutcome run_analytic_exact(const SimConfig& config, const Accel& accel, const MemoryMap& map,
                                   const StepOptions& step, RayStream& rays, RaySinkIf& sink);

/// The per-trace analysis of a whole trace: work counts of every ray, the sampled clusters
/// (every stepped ray checked through `sink`).
/// An animated trace (`frames` of more than one): each cluster lies in one frame, stepped with
/// the structure bound to it (`bind_frame`).
AnalyticProfile analyze_trace(const SimConfig& config, const Accel& accel, const MemoryMap& map,
                              const StepOptions& step, TraceReader& reader, RaySinkIf& sink,
                              const AnalyticConfig& sample, const std::vector<FrameRecord>& frames = {},
                              const std::function<void(uint32_t)>& bind_frame = {});

/// Which rays the analysis of a trace of `rays` rays steps: clusters of (warm-up, measured) in
/// trace order (sim/sampling/sampling.h's plan type; measured = the cluster's rest). With
/// `frames` (an animated trace): one cluster in each of up to `sample.clusters` frames spread
/// over the trace, the frame's middle or, for a short frame, all of it.
struct SamplePlan;
SamplePlan analysis_plan(uint64_t rays, const AnalyticConfig& sample, const SimConfig& config,
                         const std::vector<FrameRecord>& frames = {});


}  // namespace rtsim
