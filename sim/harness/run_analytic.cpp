// rtsim-sim at fidelity = analytic (sim/analytic/analytic.h): the per-trace analysis from the
// cache beside the trace, or computed once (under a lock, so a sweep's processes compute it
// once) and stored; then the estimate for this configuration and the usual outputs. A cached
// analysis needs neither the structure's image nor a pass over the rays, so a run costs little
// more than reading its config and writing its stats.
#include <chrono>
#include <cmath>
#include <functional>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>

#include "sim/harness/frames.h"
#include "sim/analytic/analytic.h"
#include "sim/analytic/analysis_cache.h"
#include "sim/analytic/closed_form.h"
#include "sim/analytic/estimate.h"
#include "sim/report/energy_area.h"
#include "sim/harness/hit_checker.h"
#include "sim/harness/memory_estimate.h"
#include "sim/report/roofline.h"
#include "sim/harness/run_files.h"
#include "sim/sampling/sampling.h"
#include "sim/report/summary.h"
#include "sim/report/stats_schema.h"
#include "sim/report/summary_schema.h"
#include "sim/report/mailbox_stats.h"
#include "sim/report/short_stack_stats.h"
#include "sim/report/box_precision_stats.h"
#include "sim/harness/structure_defaults.h"
#include "sim/harness/trace_stream.h"
#include "sim/report/verdict.h"
#include "sim/harness/verdict_check.h"
#include "traces/accel/accel_io.h"
#include "traces/common/error.h"

namespace rtsim {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

/// Computes the analysis of the trace (the structure's image loaded, the sample stepped and
/// checked through `checker`).
AnalyticProfile build_analysis(const SimConfig& c, TraceReader& reader, const std::string& rtt, HitChecker& checker,
                               const SamplePlan& plan, const AnalyticConfig& sample) {
    const std::unique_ptr<Accel> accel = load_accel(read_accel_image(reader), rtt);
    const uint64_t total = reader.section(SectionKind::rays).record_count;
    const MemoryMap map(accel->image().end_address(), total, uint64_t(c.traversal.units) * c.traversal.ray_contexts,
                        accel->max_stack_entries(), c.traversal.stack_entry_bytes);
    AnalyticProfile p = analyze_trace(c, *accel, map, reader, checker, sample);
    require(checker.checked() == plan.simulated_rays, "analytic analysis ended with " +
                                                          std::to_string(checker.checked()) + " of " +
                                                          std::to_string(plan.simulated_rays) + " sampled rays");
    p.validation = checker.to_json();
    p.workload = scan_workload(reader);
    return p;
}

/// The summary as summarize() writes it, with what this level knows from the analysis.
json analytic_summary(const SimOptions& o, const AnalyticProfile& p, const AnalyticEstimate& e,
                      const HitChecker& checker, double wall) {
    json s = summarize(o.config, Cycle(e.form.cycles), p.rays, e.model, checker, wall);
    s["hit_mismatches"] = p.validation.value("hit_mismatches", 0);
    s["work_mismatches"] = p.validation.value("work_mismatches", 0);
    s["avg_ray_latency_cycles"] = e.mean_latency;
    return s;
}

/// What a run adds to stats.json beyond the common keys; written by write_outputs.
struct RunStats {
    json summary, validation, latency, workload, instantiated, model;
    bool bad = false;  ///< a hit or work mismatch
    WorkTotals work;   ///< every ray's work (energy and area, as at the other levels)
    uint64_t rays = 0;
};

/// The whole trace's work from the analysis's sums (the WORK section's fields).
WorkTotals work_totals(const AnalyticProfile& p) {
    WorkTotals w;
    for (size_t i = 0; i < w.field.size(); ++i) w.field[i] = uint64_t(std::llround(p.work[i]));
    return w;
}

SimOutcome write_outputs(const SimOptions& o, const std::string& rtt, const json& manifest, std::time_t started,
                         RunStats r, const std::function<json(const json& model)>& verdict_of) {
    check_analytic_model(r.model);  // the blocks' declarations, as the timed levels' model is checked
    SimOutcome out;
    out.stats = {{"schema", "rtsim-stats/1"},
                 {"fidelity", kFidelityChoices.name(o.config.fidelity)},
                 {"summary", r.summary},
                 {"validation", r.validation},
                 {"latency", r.latency},
                 {"workload", r.workload},
                 {"instantiated", r.instantiated},
                 {"effects", manifest.value("workload", json::object()).value("effects", json::array())},
                 {"model", r.model},
                 {"provenance", provenance(o.command_line, rtt, manifest, started)}};
    out.stats["summary"]["sampled"] = false;
    out.stats["summary"]["frames"] = 1;  // animated traces are refused (check_frames_supported)
    add_mailbox_stats(out.stats, o.config, r.work, r.rays);
    add_short_stack_stats(out.stats, o.config, r.work, r.rays);
    add_box_precision_stats(out.stats, o.config, r.work, r.rays);
    add_energy_area(out.stats, o.config, r.work, r.rays);
    out.stats["roofline"] = roofline_json(o.config, out.stats["summary"], r.model);
    json verdict = o.verdict && out.stats["summary"].value("rays", 0) > 0 ? verdict_of(r.model) : json(nullptr);
    if (o.check_verdict && !verdict.is_null()) {
        verdict["check"] = check_verdict(o, verdict, out.stats["summary"].value("rays_per_second", 0.0));
        verdict["text"] = checked_text(verdict);
    }
    out.stats["verdict"] = verdict;
    out.stats["summary"]["bottleneck"] = verdict.is_null() ? json(nullptr) : verdict["binding"];
    out.stats["summary"]["verdict"] = verdict.is_null() ? json(nullptr) : verdict["text"];
    check_run_stats(out.stats, false);  // every key declared once, by its producer (stats_schema.h)
    write_json(fs::path(o.out_dir) / "stats.json", out.stats);
    write_json(fs::path(o.out_dir) / "provenance.json", out.stats["provenance"]);
    out.exit_code = r.bad ? 3 : 0;
    return out;
}

/// analytic.caches = functional: every ray stepped through functional caches (the exact
/// variant, exact.cpp), every ray checked.
SimOutcome run_functional_caches(const SimOptions& o, TraceReader& reader, const std::string& rtt,
                                 const json& manifest, std::time_t started,
                                 std::chrono::steady_clock::time_point t0) {
    const std::unique_ptr<Accel> accel = load_accel(read_accel_image(reader), rtt);
    apply_mailbox(*accel, o.config);
    apply_short_stack(*accel, o.config);
    apply_box_precision(*accel, o.config);
    RunStats r;
    r.workload = scan_workload(reader);
    reader.verify_all();
    const uint64_t total = r.workload["rays"];
    const TraversalConfig& tc = o.config.traversal;
    const MemoryMap map(accel->image().end_address(), total, uint64_t(tc.units) * tc.ray_contexts,
                        accel->max_stack_entries(), tc.stack_entry_bytes);
    ReferenceWindow reference(reader, o.config.dispatch.chunk_rays);
    HitChecker checker("checker", reference, total);
    TraceRayStream stream(reader);
    AnalyticOutcome a = run_analytic_exact(o.config, *accel, map, stream, checker);
    require(checker.checked() == total, "analytic run ended with " + std::to_string(checker.checked()) + " of " +
                                            std::to_string(total) + " rays finished");
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    r.summary = summarize(o.config, a.cycles, total, a.model, checker, wall);
    r.validation = checker.to_json();
    r.latency = checker.latency().to_json();
    r.instantiated = std::move(a.instantiated);
    r.model = std::move(a.model);
    r.bad = checker.hit_mismatches() || checker.work_mismatches();
    r.work = checker.work_totals();
    r.rays = checker.checked();
    const json instantiated = r.instantiated;
    return write_outputs(o, rtt, manifest, started, std::move(r), [&](const json& model) {
        VerdictContext v{o.config, model, accel.get(), &map, &reader};
        v.trace_path = rtt;
        v.instantiated = instantiated;
        return judge(v);
    });
}

}  // namespace

SimOutcome run_analytic_simulation(const SimOptions& o) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::time_t started = std::time(nullptr);
    validate(o.config);
    const std::string rtt = trace_file(o.trace);
    TraceReader reader(rtt);
    const json manifest = read_manifest(rtt);
    if (reader.has(SectionKind::frames))
        check_frames_supported(o.config, reader.section(SectionKind::frames).record_count, rtt);
    uint64_t image_bytes = 0;  // the structure's sections: what load_accel will hold
    for (const SectionInfo& s : reader.sections())
        if (s.kind != SectionKind::rays && s.kind != SectionKind::hits && s.kind != SectionKind::work)
            image_bytes += s.bytes;
    const bool functional = o.config.analytic.caches == AnalyticCaches::functional;
    check_sim_memory(o.config, image_bytes,
                     std::string("config (fidelity=analytic, analytic.caches=") +
                         (functional ? "functional" : "statistical") +
                         ", traversal.units=" + std::to_string(o.config.traversal.units) +
                         ", traversal.ray_contexts=" + std::to_string(o.config.traversal.ray_contexts) + ")");
    fs::create_directories(o.out_dir);
    write_json(fs::path(o.out_dir) / "config.resolved.json", config_to_json(o.config));
    if (o.config.analytic.caches == AnalyticCaches::functional)
        return run_functional_caches(o, reader, rtt, manifest, started, t0);

    const AnalyticConfig& sample = o.config.analytic;
    const json key = analysis_key(o.config, sample, trace_identity(reader));
    const std::string path = analysis_path(rtt, key);
    const SamplePlan plan = analysis_plan(reader.section(SectionKind::rays).record_count, sample, o.config);
    SampledReference reference(reader, plan);
    HitChecker checker("checker", reference, plan.simulated_rays);
    bool reused = true;
    std::optional<AnalyticProfile> profile = load_analysis(path, key);
    if (!profile) {
        AnalysisLock lock(path);  // another process of the sweep may be computing it
        profile = load_analysis(path, key);
        if (!profile) {
            profile = build_analysis(o.config, reader, rtt, checker, plan, sample);
            profile->key = key;
            reused = false;
            store_analysis(path, *profile);
        }
    }
    const AnalyticProfile& p = *profile;
    AnalyticEstimate e = estimate_analytic(o.config, p);
    StatsWriter(analytic_stats(), e.model["analytic"])
        .set("caches", "statistical")
        .set("analysis", json{{"file", path.empty() ? json(nullptr) : json(path)},
                              {"reused", reused},
                              {"seconds", p.analysis_seconds},
                              {"stepped_rays", p.stepped_rays},
                              {"sample_rays", p.sample_rays},
                              {"key", key}})
        .done();
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    RunStats r;
    r.summary = analytic_summary(o, p, e, checker, wall);
    r.work = work_totals(p);
    r.rays = p.rays;
    r.validation = p.validation;
    r.validation["scope"] = "the analysis's sampled rays are checked bit for bit (hit and work); every other "
                            "ray's work record is read (CRC checked) as the work counted";
    r.latency = {{"rays", p.rays}, {"mean_cycles", e.mean_latency}, {"estimated", "unloaded mean"}};
    r.workload = p.workload;
    r.instantiated = std::move(e.instantiated);
    r.model = std::move(e.model);
    r.bad = p.validation.value("hit_mismatches", 0) || p.validation.value("work_mismatches", 0);
    const json instantiated = r.instantiated;
    return write_outputs(o, rtt, manifest, started, std::move(r), [&](const json& model) {
        // The verdict's analytic estimates come from this run's own analysis (no second pass).
        VerdictContext v{o.config, model, nullptr, nullptr, nullptr};
        v.instantiated = instantiated;
        v.estimate = [form = std::make_shared<FormEstimator>(p)](const SimConfig& c) {
            const ClosedForm x = (*form)(c);
            return std::make_pair(x.cycles, x.binding);
        };
        v.estimate_method = "the analytic level's per-trace analysis (" + std::to_string(p.stepped_rays) +
                            " stepped rays)";
        return judge(v);
    });
}

}  // namespace rtsim
