#pragma once
// From a per-trace analysis (profile.h) and a configuration to the analytic level's
// answer: hit rates of the L1s and the L2 from the reuse-distance curves (reuse.h),
// traffic and unloaded latencies scaled to the whole trace by its work counts, then the closed
// form (closed_form.h). Costs microseconds to milliseconds per configuration; no ray is
// stepped, so a sweep evaluates every configuration against one analysis.
#include <memory>

#include <nlohmann/json.hpp>

#include "sim/config/config.h"
#include "sim/analytic/closed_form.h"
#include "sim/analytic/profile.h"

namespace rtsim {

struct AnalyticEstimate {
    AnalyticDemands demands;
    ClosedForm form;
    nlohmann::json model;         ///< same block names and keys as the SystemC model, plus "analytic"
    nlohmann::json instantiated;  ///< [{block, instantiated, why}]
    double mean_latency = 0;      ///< unloaded cycles per ray
};

/// Evaluates `config` against `profile`. The profile should match the config's key
/// (analysis_cache.h); when it does not (the verdict trying twice the ray contexts), the
/// estimate keeps the profile's hit rates: first order.
AnalyticEstimate estimate_analytic(const SimConfig& config, const AnalyticProfile& profile);

class MissModel;

/// The closed form of many configurations against one profile (the verdict's every knob and
/// pair): the reuse curves are built once, each cache shape's miss probabilities are kept
/// (computed once per L1 or L2 size and ways) and no model stats are written. Its form equals
/// estimate_analytic's for the same configuration and profile, which must outlive it.
class FormEstimator {
public:
    explicit FormEstimator(const AnalyticProfile& profile);
    ~FormEstimator();
    ClosedForm operator()(const SimConfig& config) const;

private:
    const AnalyticProfile& m_profile;
    std::unique_ptr<MissModel> m_misses;
};

/// Hit rates the profile predicts for one cache level: {l1: {kind: rate}, l2: ...} (tests).
struct PredictedRates {
    double l1_read_hit_rate = 0;  ///< over all line reads
    double l2_read_hit_rate = 0;  ///< over the L1's read misses
    double dram_read_lines = 0;   ///< line reads reaching DRAM, whole trace
};
PredictedRates predicted_rates(const SimConfig& config, const AnalyticProfile& profile);

/// An animated trace's hit rates frame by frame: each analysed frame's from its own reads (its
/// miss ratios scaled so that their mean over the analysed frames is the run's: the frames' keys
/// are octaves), the frames between two analysed ones interpolated, those before the first and
/// after the last the nearest's. Empty without frame samples.
std::vector<PredictedRates> frame_hit_rates(const SimConfig& config, const AnalyticProfile& profile, size_t frames);

}  // namespace rtsim
