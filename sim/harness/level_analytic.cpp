// The analytic level (sim/analytic/analytic.h): the per-trace analysis from the cache beside the
// trace, or computed once (under a lock, so a sweep's processes compute it once) and stored; then
// the estimate for this configuration. A cached analysis needs neither the structure's image nor
// a pass over the rays, so a run costs little more than reading its config and writing its stats.
// With analytic.caches = functional every ray is stepped through functional caches instead.
#include <cmath>
#include <memory>
#include <optional>

#include "sim/analytic/analysis_cache.h"
#include "sim/analytic/analytic.h"
#include "sim/analytic/closed_form.h"
#include "sim/analytic/estimate.h"
#include "sim/harness/analytic_frames.h"
#include "sim/harness/frame_builds.h"
#include "sim/harness/frames.h"
#include "sim/harness/hit_checker.h"
#include "sim/harness/level.h"
#include "sim/harness/memory_estimate.h"
#include "sim/harness/run_files.h"
#include "sim/harness/trace_stream.h"
#include "sim/report/summary.h"
#include "sim/sampling/sampling.h"
#include "traces/accel/accel_io.h"
#include "traces/common/error.h"

namespace rtsim {

using nlohmann::json;

namespace {

/// Computes the analysis of the trace (the structure's image loaded, the sample stepped and
/// checked through `checker`).
AnalyticProfile build_analysis(const RunInputs& in, TraceReader& reader, HitChecker& checker, const SamplePlan& plan,
                               Accel* animated, const std::vector<FrameRecord>& frames) {
    const SimConfig& c = in.config();
    std::unique_ptr<Accel> loaded;
    if (!animated) loaded = load_accel(read_accel_image(reader), in.rtt);
    Accel& accel = animated ? *animated : *loaded;
    const uint64_t total = reader.section(SectionKind::rays).record_count;
    const MemoryMap map(accel.image().end_address(), total, uint64_t(c.traversal.units) * c.traversal.contexts(),
                        accel.max_stack_entries(), c.traversal.stack_entry_bytes);
    AnalyticProfile p = analyze_trace(c, accel, map, in.setup.step, reader, checker, c.analytic, frames,
                                      [&accel](uint32_t f) { accel.bind_frame(f); });
    require(checker.checked() == plan.simulated_rays, "analytic analysis ended with " +
                                                          std::to_string(checker.checked()) + " of " +
                                                          std::to_string(plan.simulated_rays) + " sampled rays");
    p.validation = checker.to_json();
    p.workload = scan_workload(reader);
    return p;
}

/// The whole trace's work from the analysis's sums (the WORK section's fields).
WorkTotals work_totals(const AnalyticProfile& p) {
    WorkTotals w;
    for (size_t i = 0; i < w.field.size(); ++i) w.field[i] = uint64_t(std::llround(p.work[i]));
    return w;
}

/// The structure's sections: what load_accel would hold.
uint64_t image_bytes(const TraceReader& reader) {
    uint64_t bytes = 0;
    for (const SectionInfo& s : reader.sections())
        if (s.kind != SectionKind::rays && s.kind != SectionKind::hits && s.kind != SectionKind::work) bytes += s.bytes;
    return bytes;
}

/// analytic.caches = functional: every ray stepped through functional caches (the exact
/// variant, exact.cpp), every ray checked.
LevelResult run_functional_caches(RunInputs& in) {
    BuiltRun built = build_run(in, false);
    const SimConfig& c = in.config();
    ReferenceWindow reference(in.reader, c.dispatch.chunk_rays);
    HitChecker checker("checker", reference, built.rays);
    // Every ray is stepped: any-hit rays in another child order are checked by occlusion.
    checker.set_reordered_anyhit(in.setup.step.reorders_anyhit());
    TraceRayStream stream(in.reader);
    AnalyticOutcome a = run_analytic_exact(c, *built.accel, *built.map, in.setup.step, stream, checker);
    require(checker.checked() == built.rays, "analytic run ended with " + std::to_string(checker.checked()) + " of " +
                                                 std::to_string(built.rays) + " rays finished");
    LevelResult r;
    r.cycles = a.cycles;
    r.summary = summarize(c, a.cycles, built.rays, a.model,
                          {checker.hit_mismatches(), checker.work_mismatches(), checker.latency().mean()},
                          in.wall_seconds());
    r.validation = checker.to_json();
    r.latency = checker.latency().to_json();
    r.workload = built.workload;
    r.instantiated = std::move(a.instantiated);
    r.model = std::move(a.model);
    r.bad = checker.hit_mismatches() || checker.work_mismatches();
    r.work = checker.work_totals();
    r.rays = checker.checked();
    auto kept = std::make_shared<BuiltRun>(std::move(built));
    r.judge = [&in, kept, instantiated = r.instantiated](const json& model) {
        return judge(verdict_context(in, *kept, model, instantiated));
    };
    return r;
}

/// analytic.caches = statistical: the per-trace analysis (stored, or computed and stored) and
/// the closed form for this config.
LevelResult run_statistical(RunInputs& in) {
    const SimConfig& c = in.config();
    const AnalyticConfig& sample = c.analytic;
    const json key = analysis_key(c, sample, trace_identity(in.reader));
    const std::string path = analysis_path(in.rtt, key);
    // An animated trace: its structure (bound frame by frame for the analysis, its builds for the
    // estimate) and its frame table.
    std::unique_ptr<Accel> animated;
    std::vector<FrameRecord> frames;
    if (in.reader.has(SectionKind::frames)) {
        animated = load_accel(read_accel_image(in.reader), in.rtt);
        frames = read_frame_table(in.reader, animated->frame_count());
    }
    const SamplePlan plan = analysis_plan(in.reader.section(SectionKind::rays).record_count, sample, c, frames);
    SampledReference reference(in.reader, plan);
    HitChecker checker("checker", reference, plan.simulated_rays);
    bool reused = true;
    std::optional<AnalyticProfile> profile = load_analysis(path, key);
    if (!profile) {
        AnalysisLock lock(path);  // another process of the sweep may be computing it
        profile = load_analysis(path, key);
        if (!profile) {
            profile = build_analysis(in, in.reader, checker, plan, animated.get(), frames);
            profile->key = key;
            reused = false;
            store_analysis(path, *profile);
        }
    }
    auto p = std::make_shared<const AnalyticProfile>(std::move(*profile));
    AnalyticEstimate e = estimate_analytic(c, *p);
    StatsWriter(analytic_stats(), e.model["analytic"])
        .set("caches", "statistical")
        .set("analysis", json{{"file", path.empty() ? json(nullptr) : json(path)},
                              {"reused", reused},
                              {"seconds", p->analysis_seconds},
                              {"stepped_rays", p->stepped_rays},
                              {"sample_rays", p->sample_rays},
                              {"key", key}})
        .done();
    LevelResult r;
    r.cycles = Cycle(e.form.cycles);
    r.summary = summarize(c, r.cycles, p->rays, e.model, {}, in.wall_seconds());
    if (frames.size() > 1) {
        // Frames: the closed form's traversal shared out by frame, each barrier's refill, each
        // frame's builds on the build unit (analytic_frames.h).
        std::vector<std::vector<BuildJob>> jobs = frame_build_jobs(*animated);
        if (c.build_unit.overlap) move_to_second_buffer(jobs);
        const AnalyticFrames af = estimate_frames(c, frames, frame_step_work(in.reader, frames),
                                                  in.manifest.value("frames", json(nullptr)), jobs, e.form.cycles,
                                                  e.mean_latency, r.summary, frame_hit_rates(c, *p, frames.size()));
        r.cycles = af.cycles;
        r.frames = af.frames;
        r.frame_count = frames.size();
        if (!af.build_unit.is_null()) {
            e.model["build_unit"] = af.build_unit;
            e.instantiated.push_back({{"block", "build_unit"}, {"instantiated", true},
                                      {"why", c.build_unit.overlap
                                                  ? "a moving scene: each frame's structures are built or refit beside "
                                                    "the previous frame's rays (closed form: the DRAM at its peak rate, "
                                                    "the traversal's loaded latency, both bound by the DRAM's bandwidth)"
                                                  : "a moving scene: each frame's structures are built or refit at its "
                                                    "barrier (closed form: the DRAM at its peak rate)"}});
        }
        r.summary = summarize(c, r.cycles, p->rays, e.model, {}, in.wall_seconds());
    }
    r.summary["hit_mismatches"] = p->validation.value("hit_mismatches", 0);
    r.summary["work_mismatches"] = p->validation.value("work_mismatches", 0);
    r.summary["avg_ray_latency_cycles"] = e.mean_latency;
    r.work = work_totals(*p);
    r.rays = p->rays;
    r.validation = p->validation;
    r.validation["scope"] = "the analysis's sampled rays are checked bit for bit (hit and work); every other "
                            "ray's work record is read (CRC checked) as the work counted";
    r.latency = {{"rays", p->rays}, {"mean_cycles", e.mean_latency}, {"estimated", "unloaded mean"}};
    r.workload = p->workload;
    r.instantiated = std::move(e.instantiated);
    r.model = std::move(e.model);
    r.bad = p->validation.value("hit_mismatches", 0) || p->validation.value("work_mismatches", 0);
    r.judge = [&in, p, instantiated = r.instantiated](const json& model) {
        // The verdict's analytic estimates come from this run's own analysis (no second pass).
        VerdictContext v{in.config(), model, nullptr, nullptr};
        v.instantiated = with_structure_blocks(instantiated, in.setup.structure);
        v.structure = structure_traits(in);
        v.unit = unit_traits(in.setup);
        const auto form = std::make_shared<FormEstimator>(*p);
        v.estimate = [form](const SimConfig& x) {
            const ClosedForm f = (*form)(x);
            return std::make_pair(f.steady_cycles, f.binding);
        };
        const ClosedForm own = (*form)(in.config());
        v.phase_cycles = std::max(0.0, own.cycles - own.steady_cycles);
        v.estimate_bytes = [form](const SimConfig& x) { return (*form)(x).dram_bytes; };
        v.estimate_method = "the analytic level's per-trace analysis (" + std::to_string(p->stepped_rays) +
                            " stepped rays)";
        return judge(v);
    };
    return r;
}

}  // namespace

LevelResult run_analytic_level(RunInputs& in) {
    const SimConfig& c = in.config();
    const bool functional = c.analytic.caches == AnalyticCaches::functional;
    check_sim_memory(c, image_bytes(in.reader),
                     std::string("config (fidelity=analytic, analytic.caches=") +
                         (functional ? "functional" : "statistical") +
                         ", traversal.units=" + std::to_string(c.traversal.units) +
                         ", traversal.ray_contexts=" + std::to_string(c.traversal.contexts()) + ")");
    LevelResult r = functional ? run_functional_caches(in) : run_statistical(in);
    check_analytic_model(r.model, c.traversal.model);  // the blocks' declarations, as the timed levels' model is checked
    if (functional) r.frames = nullptr;  // functional caches replay no frames (resolve refuses animated traces)
    return r;
}

}  // namespace rtsim
