#pragma once
// The verdict's estimator (sim/report/verdict.h): the analytic level's closed form evaluated for
// any config against one per-trace analysis, so weighing every knob and pair costs
// milliseconds, not a pass over rays per knob. The analysis is, in order of preference: the one
// the analytic level itself computed (its run passes it), the per-trace analysis stored beside
// the trace for this config's key (analysis_cache.h), or one pass over a sample of the trace's
// rays (evenly spread blocks, of the first frame in an animated trace).
#include <memory>
#include <string>
#include <utility>

#include "sim/analytic/profile.h"
#include "sim/config/config.h"

namespace rtsim {

struct VerdictContext;

/// The config the analytic level can run: no treelets (its closed form models plain dispatch)
/// and no sampling (it runs on its own analysis).
SimConfig analytic_config(SimConfig config);

class VerdictEstimator {
public:
    explicit VerdictEstimator(const VerdictContext& context);
    /// The analytic level's cycles and binding bound for `config` (made analytic_config first).
    std::pair<double, std::string> operator()(const SimConfig& config) const;
    /// How the estimates are made, for the verdict's text.
    const std::string& method() const { return m_method; }

private:
    const VerdictContext& m_context;
    std::unique_ptr<AnalyticProfile> m_loaded;  ///< a stored per-trace analysis, when one was found
    const AnalyticProfile* m_profile = nullptr;
    std::string m_method;
};

}  // namespace rtsim
