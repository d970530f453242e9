#pragma once
// The verdict's estimator (sim/report/verdict.h): the analytic level's closed form evaluated for
// any config against one per-trace analysis, so weighing every knob and pair costs
// milliseconds, not a pass over rays per knob. The analysis is, in order of preference: the one
// the analytic level itself computed (its run passes it), the per-trace analysis stored beside
// the trace for this config's key (analysis_cache.h), or the verdict's own analysis of a sample
// of the trace's rays (evenly spread blocks, of the first frame in an animated trace), which the
// first run that needs it steps and stores beside the trace, so every later run of the trace
// with the same key (a sweep's, a re-run's) loads it instead of stepping rays.
#include <memory>
#include <string>
#include <utility>

#include "sim/analytic/estimate.h"
#include "sim/analytic/profile.h"
#include "sim/config/config.h"
#include "sim/report/dram_latency_calibration.h"
#include "sim/report/verdict_knobs.h"

namespace rtsim {

struct VerdictContext;

/// The config the analytic level runs the estimates at: its statistical caches (they cost
/// lock-step groups and treelet scheduling), no sampling (it runs on its own analysis), and the
/// unit kind `estimate_as` instead of one it cannot cost ("" keeps the config's).
SimConfig analytic_config(SimConfig config, const std::string& estimate_as);

class VerdictEstimator {
public:
    explicit VerdictEstimator(const VerdictContext& context);
    /// The analytic level's cycles and binding bound for `config` (made analytic_config first).
    std::pair<double, std::string> operator()(const SimConfig& config) const;
    /// The DRAM bytes the estimate moves for `config` (0 when the estimator does not say).
    double dram_bytes(const SimConfig& config) const;
    /// A structural alternative of `config` (the run's): the analytic level on its own analysis of
    /// the same sample of rays, against the run's design on that sample. Another structure reads
    /// the alternative trace beside the run's (VerdictContext::alternative); another execution
    /// model or treelets flipped analyse the run's trace under the relaxed config. Both designs'
    /// analyses are stored beside their traces, so later runs load them.
    StructuralEstimate structural(const Knob& knob, const SimConfig& config) const;
    /// The cycles the run's phases (fill and drain) add to its steady state, at the run's own
    /// config: every estimate is a steady state plus these (0 when the analysis kept no phases).
    /// The fill and drain are latency-bound, so a knob that speeds the steady state leaves them
    /// (Amdahl): on a short trace its gain is that much smaller than the steady state's.
    double phase_cycles() const;
    /// How the estimates are made, for the verdict's text.
    const std::string& method() const { return m_method; }
    /// True when the analysis was loaded from beside the trace (not stepped by this run).
    bool reused() const { return m_reused; }
    /// The DRAM latency the estimates charge beyond dram.latency, from the judged run's bank
    /// model (dram_latency_calibration.h); nothing measured when the run is not timed.
    const DramLatencyCalibration& dram_calibration() const { return m_dram; }

private:
    const VerdictContext& m_context;
    std::unique_ptr<AnalyticProfile> m_loaded;  ///< a stored per-trace analysis, when one was found
    const AnalyticProfile* m_profile = nullptr;
    std::unique_ptr<FormEstimator> m_form;  ///< the closed form of each config against m_profile
    bool m_form_is_sample = false;          ///< m_profile is the verdict's own sample analysis
    /// The run's design on the verdict's sample, when m_profile is another analysis (the
    /// analytic level's, a stored per-trace one): what structural estimates compare against.
    mutable std::unique_ptr<AnalyticProfile> m_sample;
    mutable std::unique_ptr<FormEstimator> m_sample_form;
    const FormEstimator& sample_form() const;
    /// The verdict's analysis of its sample of the run's own trace for `config` (stored beside
    /// the trace, or loaded from there: `reused`).
    std::unique_ptr<AnalyticProfile> own_sample(const SimConfig& config, bool* reused) const;
    std::string m_method;
    bool m_reused = false;
    mutable double m_phase_cycles = -1;  ///< phase_cycles(), once computed
    DramLatencyCalibration m_dram;
    /// analytic_config of `config` with the calibrated DRAM latency: what every estimate times.
    SimConfig estimated_config(const SimConfig& config) const;
};

}  // namespace rtsim
