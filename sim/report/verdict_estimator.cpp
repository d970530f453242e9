#include "sim/report/verdict_estimator.h"

#include <algorithm>
#include <optional>

#include "sim/analytic/analysis_cache.h"
#include "sim/analytic/analytic.h"
#include "sim/analytic/estimate.h"
#include "sim/report/verdict.h"

namespace rtsim {

namespace {

class DiscardSink : public RaySinkIf {
public:
    void ray_done(const RayResult&) override {}
};

}  // namespace

SimConfig analytic_config(SimConfig config, const std::string& estimate_as) {
    config.fidelity = Fidelity::analytic;
    config.analytic.caches = AnalyticCaches::statistical;  // the level that costs every kind and treelets
    config.sampling = SamplingConfig{};
    // The closed form times each ray context on its own: a lock-step kind's relaxations are
    // estimated for the kind that stands in for it with the same contexts (divergence is not in it).
    if (!estimate_as.empty()) config.traversal.model = estimate_as;
    return config;
}

namespace {

/// The key of the verdict's own sample analysis stored beside the trace: the per-trace key's
/// trace and machine fields (what the access streams depend on) and the sample's rays instead
/// of the analytic level's sample parameters.
nlohmann::json verdict_sample_key(const SimConfig& base, const std::string& identity, uint64_t first_ray,
                                  uint64_t rays, uint64_t sample_rays) {
    nlohmann::json key = analysis_key(base, base.analytic, identity);
    key.erase("sample");
    key["verdict_sample"] = {{"first_ray", first_ray}, {"rays", rays}, {"sample_rays", sample_rays}};
    return key;
}

}  // namespace

VerdictEstimator::VerdictEstimator(const VerdictContext& c) : m_context(c) {
    // A timed run's own DRAM figures: the row outcomes and bank waits the closed form leaves out.
    if (c.config.fidelity == Fidelity::approx || c.config.fidelity == Fidelity::detailed)
        m_dram = calibrate_dram_latency(c.config, c.model.contains("dram") ? c.model["dram"] : nlohmann::json());
    if (c.estimate) {
        m_method = c.estimate_method;
        return;
    }
    const SimConfig base = analytic_config(c.config, c.unit.estimate_as);
    const std::string identity = c.trace_path.empty() ? std::string() : c.identity;
    // The analysis stored beside the trace for this key, if a run at the analytic level made it.
    if (c.frames == 1 && !c.trace_path.empty()) {
        const nlohmann::json key = analysis_key(base, base.analytic, identity);
        if (auto stored = load_analysis(analysis_path(c.trace_path, key), key)) {
            m_loaded = std::make_unique<AnalyticProfile>(std::move(*stored));
            m_profile = m_loaded.get();
            m_method = "the analytic level on the per-trace analysis stored beside the trace (" +
                       std::to_string(uint64_t(m_profile->stepped_rays)) + " stepped rays)";
            m_form = std::make_unique<FormEstimator>(*m_profile);
            m_reused = true;
            return;
        }
    }
    const uint64_t rays = c.frame_rays ? c.frame_rays : c.trace_rays;
    const std::unique_ptr<RayStream> sample = c.sample_stream(c.first_ray, rays, c.sample_rays);
    RayStream& stream = *sample;
    m_method = "analytic level on " + std::to_string(stream.total_rays()) + " sampled rays" +
               (c.frames > 1 ? " of the first frame" : "") + (c.config.treelets.enabled ? " in treelet order" : "");
    // Else the verdict's own sample analysis: stored beside the trace by the first run that
    // needs it (under a lock, as a sweep's processes share it), loaded by every later one.
    const nlohmann::json key =
        identity.empty() ? nlohmann::json() : verdict_sample_key(base, identity, c.first_ray, rays, c.sample_rays);
    const std::string path = identity.empty() ? std::string() : analysis_path(c.trace_path, key);
    std::optional<AnalyticProfile> stored = load_analysis(path, key);
    if (!stored) {
        AnalysisLock lock(path);
        stored = load_analysis(path, key);
        if (!stored) {
            DiscardSink sink;
            m_profile = &analyze_stream(base, *c.accel, *c.map, c.step, stream, sink);
            if (!path.empty()) {
                AnalyticProfile keyed = *m_profile;
                keyed.key = key;
                store_analysis(path, keyed);
            }
            m_form = std::make_unique<FormEstimator>(*m_profile);
            return;
        }
    }
    m_loaded = std::make_unique<AnalyticProfile>(std::move(*stored));
    m_profile = m_loaded.get();
    m_form = std::make_unique<FormEstimator>(*m_profile);
    m_reused = true;
}


SimConfig VerdictEstimator::estimated_config(const SimConfig& config) const {
    return m_dram.apply(analytic_config(config, m_context.unit.estimate_as));
}

double VerdictEstimator::dram_bytes(const SimConfig& config) const {
    const SimConfig a = estimated_config(config);
    if (m_context.estimate_bytes) return m_context.estimate_bytes(a);
    return m_form ? (*m_form)(a).dram_bytes : 0.0;
}

std::pair<double, std::string> VerdictEstimator::operator()(const SimConfig& config) const {
    const SimConfig a = estimated_config(config);
    if (m_context.estimate) return m_context.estimate(a);
    const ClosedForm form = (*m_form)(a);
    return {form.cycles, form.binding};
}

}  // namespace rtsim
