#include "sim/report/verdict_estimator.h"

#include <algorithm>
#include <optional>

#include "sim/analytic/analysis_cache.h"
#include "sim/analytic/analytic.h"
#include "sim/analytic/estimate.h"
#include "sim/report/verdict.h"
#include "traces/common/error.h"

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

namespace {

/// The verdict's own analysis of `sample_rays` rays of [first, first + rays) of a trace for the
/// config `base`: loaded from beside the trace when a run stored it for this key, else stepped
/// and stored there (under a lock, as a sweep's processes share it). `reused` says which.
std::unique_ptr<AnalyticProfile> sample_analysis(const SimConfig& base, const Accel& accel, const MemoryMap& map,
                                                 const StepOptions& step, const SampleStreamFactory& streams,
                                                 const std::string& identity, const std::string& trace_path,
                                                 uint64_t first, uint64_t rays, uint64_t sample_rays, bool* reused) {
    const nlohmann::json key =
        identity.empty() ? nlohmann::json() : verdict_sample_key(base, identity, first, rays, sample_rays);
    const std::string path = identity.empty() ? std::string() : analysis_path(trace_path, key);
    std::optional<AnalyticProfile> stored = load_analysis(path, key);
    if (!stored) {
        AnalysisLock lock(path);
        stored = load_analysis(path, key);
        if (!stored) {
            DiscardSink sink;
            const std::unique_ptr<RayStream> stream = streams(first, rays, sample_rays);
            // A copy: analyze_stream keeps only a handful of analyses, and a verdict may make more.
            auto profile = std::make_unique<AnalyticProfile>(analyze_stream(base, accel, map, step, *stream, sink));
            if (sample_rays < rays) {
                // A sample of the trace: its fill and drain are the sample's, not the run's.
                profile->phases.clear();
                profile->group.phases.clear();
            }
            if (!path.empty()) {
                AnalyticProfile keyed = *profile;
                keyed.key = key;
                store_analysis(path, keyed);
            }
            *reused = false;
            return profile;
        }
    }
    *reused = true;
    return std::make_unique<AnalyticProfile>(std::move(*stored));
}

/// The kind whose analytic estimate stands in for `config`'s unit kind ("" when the level costs
/// the kind itself: unit_traits in sim/harness/run_inputs.h).
std::string stand_in_of(const SimConfig& config) {
    const UnitKind& u = config.traversal.kind();
    return u.needs.lock_step && !u.group_profile ? u.estimate_as : std::string();
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
    m_loaded = own_sample(base, &m_reused);
    m_profile = m_loaded.get();
    m_form = std::make_unique<FormEstimator>(*m_profile);
    m_form_is_sample = true;
    m_method = "analytic level on " + std::to_string(uint64_t(m_profile->stepped_rays)) + " sampled rays" +
               (c.frames > 1 ? " of the first frame" : "") + (c.config.treelets.enabled ? " in treelet order" : "");
}

std::unique_ptr<AnalyticProfile> VerdictEstimator::own_sample(const SimConfig& config, bool* reused) const {
    const VerdictContext& c = m_context;
    return sample_analysis(config, *c.accel, *c.map, c.step, c.sample_stream,
                           c.trace_path.empty() ? std::string() : c.identity, c.trace_path, c.first_ray,
                           c.frame_rays ? c.frame_rays : c.trace_rays, c.sample_rays, reused);
}

const FormEstimator& VerdictEstimator::sample_form() const {
    if (m_form_is_sample) return *m_form;
    if (!m_sample_form) {
        bool reused = false;
        m_sample = own_sample(analytic_config(m_context.config, m_context.unit.estimate_as), &reused);
        m_sample_form = std::make_unique<FormEstimator>(*m_sample);
    }
    return *m_sample_form;
}

StructuralEstimate VerdictEstimator::structural(const Knob& k, const SimConfig& config) const {
    const VerdictContext& c = m_context;
    StructuralEstimate out;
    // The stand-in kinds' estimates are the stand-in's: no execution model is estimated there.
    const bool model = k.relax.key == "traversal.model";
    if (!k.trace && !model && k.relax.key != "treelets.enabled") {
        out.why_not = "the analytic level does not model it";
        return out;
    }
    if (c.frames > 1 || !c.sample_stream) {
        out.why_not = "the trace is animated";
        return out;
    }
    try {
        // Steady-state cycles on both sides plus the run's phases: an alternative's analysis may
        // keep no phases (treelets, lock-step kinds), and a phased base against it would favour it.
        const double base =
            sample_form()(m_dram.apply(analytic_config(config, c.unit.estimate_as))).steady_cycles + phase_cycles();
        bool reused = false;
        double cycles = 0;
        if (k.trace) {
            std::string why;
            const std::unique_ptr<AlternativeTrace> alt =
                c.alternative ? c.alternative(k.relax.key, value_text(k.relax.to), &why) : nullptr;
            if (!alt) {
                out.why_not = why.empty() ? "no alternative trace" : why;
                return out;
            }
            const SimConfig a = analytic_config(alt->config, stand_in_of(alt->config));
            const auto profile = sample_analysis(a, *alt->accel, *alt->map, alt->step, alt->sample_stream,
                                                 alt->identity, alt->path, 0, alt->rays, c.sample_rays, &reused);
            cycles = FormEstimator(*profile)(m_dram.apply(a)).steady_cycles + phase_cycles();
            out.method = "the analytic level on the same " + std::to_string(uint64_t(profile->stepped_rays)) +
                         " sampled rays of the alternative trace beside this one";
        } else {
            const SimConfig relaxed = relaxed_config(config, {k.relax});
            const std::string as = stand_in_of(relaxed);
            if (model && (!as.empty() || !c.unit.estimate_as.empty())) {
                out.why_not = "the analytic level has no lock-step groups for one of the two kinds";
                return out;
            }
            const SimConfig a = analytic_config(relaxed, as);
            const auto profile = own_sample(a, &reused);
            cycles = FormEstimator(*profile)(m_dram.apply(a)).steady_cycles + phase_cycles();
            out.method = "the analytic level on the same " + std::to_string(uint64_t(profile->stepped_rays)) +
                         " sampled rays with " + setting_text(k.relax);
        }
        if (!(cycles > 0) || !(base > 0)) {
            out.why_not = "the analytic level gave no cycles";
            return out;
        }
        out.speedup = base / cycles;
    } catch (const std::exception& e) {  // a refused config, a bad alternative, the filesystem
        out.why_not = e.what();
    }
    return out;
}

SimConfig VerdictEstimator::estimated_config(const SimConfig& config) const {
    return m_dram.apply(analytic_config(config, m_context.unit.estimate_as));
}

double VerdictEstimator::dram_bytes(const SimConfig& config) const {
    const SimConfig a = estimated_config(config);
    if (m_context.estimate_bytes) return m_context.estimate_bytes(a);
    return m_form ? (*m_form)(a).dram_bytes : 0.0;
}

double VerdictEstimator::phase_cycles() const {
    if (m_phase_cycles >= 0) return m_phase_cycles;
    m_phase_cycles = 0;
    if (m_context.estimate) {
        m_phase_cycles = std::max(0.0, m_context.phase_cycles);
    } else if (m_form) {
        const ClosedForm f = (*m_form)(estimated_config(m_context.config));
        m_phase_cycles = std::max(0.0, f.cycles - f.steady_cycles);
    }
    return m_phase_cycles;
}

std::pair<double, std::string> VerdictEstimator::operator()(const SimConfig& config) const {
    const SimConfig a = estimated_config(config);
    // A steady state plus the run's phases, as the structural alternatives': the phases are the
    // analysed machine's (a knob of more units or contexts has no windows of its own on this
    // analysis), and fill and drain, bound by latency, stay when a knob speeds the steady state.
    if (m_context.estimate) {
        const auto [steady, binding] = m_context.estimate(a);
        return {steady + phase_cycles(), binding};
    }
    const ClosedForm form = (*m_form)(a);
    return {form.steady_cycles + phase_cycles(), form.binding};
}

}  // namespace rtsim
