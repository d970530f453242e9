#pragma once
// Why is this design slow? (docs/stats.md, "verdict"). After a run, the verdict names the
// binding resource with its evidence, what relaxing each resource would buy, and what to try:
//
//   1. evidence: at the timed levels, the shares of the ray contexts' cycles that point at each
//      resource (cycle accounting: e.g. waiting for a free L1 MSHR), refined by utilisation (DRAM
//      data waits with the channels near peak are bandwidth, otherwise latency; an L1 whose
//      misses queue at a saturated L2 MSHR file points at the L2's MSHRs too).
//   2. every knob (verdict_knobs.h): each resource's config field relaxed one step (doubled,
//      or a cost halved), estimated by the analytic level on the run's analysis
//      (verdict_estimator.h), priced by the area model; ranked by gain and by gain per mm^2;
//      pairs that gain much more together than alone are co-limits.
//   3. the binding resource: the best knob's, when it buys 2% or more; else the largest
//      cycle use's. Where the analytic level does not model the machine (treelet admission and
//      queues), nothing is estimated: the knobs are ranked by evidence and the verdict says to
//      measure (verdict_check.h, `--check-verdict`), never a confident wrong answer.
//   First order: the analytic level has its own error (docs/fidelity.md); an estimate of
//   direction and size, not a promise; `--check-verdict` measures the top candidates.
#include <cstdint>
#include <functional>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

#include "rtl_model/common/interfaces.h"
#include "rtl_model/common/stats.h"
#include "rtl_model/common/memory_map.h"
#include "rtl_model/dispatch/dispatch.h"
#include "sim/config/config.h"
#include "traces/accel/accel.h"
#include "sim/report/verdict_knobs.h"

namespace rtsim {

/// The knob that relaxes a resource (names of the analytic bounds: "l2_mshrs", "dram", "box",
/// "scheduler", "latency", ...), doubled; an empty key when no knob does.
Relaxation relaxation_for(const std::string& resource, const SimConfig& config);

/// Evenly spread blocks of `sample` rays of rays [first, first + rays) of the run's trace: the
/// rays the verdict's own analysis steps (the run loop reads them: sim/harness/trace_stream.h).
using SampleStreamFactory = std::function<std::unique_ptr<RayStream>(uint64_t first, uint64_t rays, uint64_t sample)>;

/// A structural alternative's trace, opened: another structure over the same rays, traced
/// beside the run's by `rtsim trace --alternatives` (sim/harness/alternative_trace.h). The
/// verdict's estimate of the alternative is the analytic level on the same sample of its rays.
struct AlternativeTrace {
    virtual ~AlternativeTrace() = default;
    std::string path;       ///< its .rtt (its analysis is stored beside it)
    std::string identity;   ///< its identity (analysis_cache.h)
    const Accel* accel = nullptr;
    const MemoryMap* map = nullptr;
    SimConfig config;       ///< the run's config resolved against its structure
    StepOptions step = {};  ///< what its steppers walk with (the same resolution's)
    uint64_t rays = 0;
    SampleStreamFactory sample_stream = {};
};

/// The alternative trace for `key=value` (StructureAlternative), or null with `why` (none was
/// traced, its rays are not the run's, the config refuses its structure).
using AlternativeFactory =
    std::function<std::unique_ptr<AlternativeTrace>(const std::string& key, const std::string& value, std::string* why)>;

struct VerdictContext {
    const SimConfig& config;
    const nlohmann::json& model;  ///< the run's model stats (cycle accounting, utilisation, ...)
    const Accel* accel;           ///< the structure, its memory map and the trace's rays: the
    const MemoryMap* map;         ///< sample the analytic estimates run on (unless `estimate` is set)
    SampleStreamFactory sample_stream = {};
    StepOptions step = {};        ///< what the sample's steppers walk with (the run's)
    std::string identity = {};    ///< the trace's identity (analysis_cache.h), "" when none
    uint64_t trace_rays = 0;      ///< rays in the trace
    /// The run's unit kind as the verdict needs it (the resolution step's, sim/resolve/resolve.h).
    UnitTraits unit = {};
    uint64_t sample_rays = 8192;  ///< rays the analytic estimates run on (evenly spread blocks)
    /// When set, the analytic estimates (steady-state cycles, binding bound) come from it instead:
    /// the analytic level passes its own per-trace analysis, so it needs no second pass over rays.
    std::function<std::pair<double, std::string>(const SimConfig&)> estimate = {};
    /// With `estimate`: the cycles the run's phases (fill and drain) add to its steady state at
    /// the run's own config (VerdictEstimator::phase_cycles); unset (< 0): none known.
    double phase_cycles = -1;
    std::string estimate_method = {};  ///< how `estimate` estimates, for the verdict's text
    /// With `estimate`: the DRAM bytes its estimate moves for a config (unset: not known).
    std::function<double(const SimConfig&)> estimate_bytes = {};
    std::string trace_path = {};       ///< the .rtt: a per-trace analysis stored beside it is reused
    size_t frames = 1;                 ///< an animated trace's frames: the sample is the first frame's
    uint64_t first_ray = 0, frame_rays = 0;  ///< that frame's rays (0: the whole trace)
    nlohmann::json instantiated = nlohmann::json::array();  ///< the run's blocks (the area model's input)
    StructureTraits structure = {};  ///< the run's structure, for the structural knobs
    AlternativeFactory alternative = {};  ///< unset: no structural alternative is estimated
};

/// {binding, label, evidence, relax, candidates, top, top_per_mm2, co_limits, coverage, estimate,
/// analytic_binding, text}; null for the functional level.
nlohmann::json judge(const VerdictContext& context);
/// The shading side's knobs beside the RT unit's top ones, weighed by what they buy the frame
/// (verdict "frame", only in runs that model the frame).
nlohmann::json frame_knobs(const nlohmann::json& shading, const nlohmann::json& weighed, const SimConfig& config);
/// A moving scene's build unit knobs beside the RT unit's best, by what each buys the run.
nlohmann::json build_knobs(const nlohmann::json& build_unit, const nlohmann::json& weighed, const SimConfig& config);

/// stats.json "verdict", declared once.
const StatBlock& verdict_stats();

}  // namespace rtsim
