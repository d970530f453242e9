// The timed levels (approx, detailed): the SystemC model over the whole trace or, with sampling,
// over a stratified sample of it (sim/sampling/sampling.h) with functional warming; animated
// traces replayed frame after frame with caches warm.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <memory>

#include "rtl_model/build_unit/build_streamer.h"
#include "rtl_model/shading/shading_block.h"
#include "rtl_model/top/top.h"
#include "sim/config/config.h"
#include "sim/harness/frame_builds.h"
#include "sim/harness/frames.h"
#include "sim/harness/hit_checker.h"
#include "sim/harness/level.h"
#include "sim/harness/model_errors.h"
#include "sim/harness/shading_run.h"
#include "sim/harness/trace_stream.h"
#include "sim/report/summary.h"
#include "sim/report/timeline.h"
#include "sim/sampling/sampling.h"
#include "sim/sampling/warming.h"
#include "traces/common/error.h"

namespace rtsim {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

/// The config the SystemC model times with. Detailed: units synchronise every cycle (quantum 1),
/// so shared blocks see requests in time order (docs/model.md, "The detailed level"); approx with
/// treelets: a shorter quantum (treelets.quantum_cycles; docs/fidelity.md). The resolved config
/// keeps the user's value.
SimConfig timed_config(const SimConfig& c) {
    SimConfig t = c;
    if (c.fidelity == Fidelity::detailed) t.quantum_cycles = 1;
    else if (c.treelets.enabled) t.quantum_cycles = std::min(t.quantum_cycles, c.treelets.quantum_cycles);
    return t;
}

/// RUN/dram_trace.dramsim3.txt, dram_requests.csv and dram_trace.json (the summary and the
/// DRAM config the stream was timed with, for the replaying script).
void write_dram_trace(const DramRequestLog& log, const SimConfig& c, bool has_dram, const std::string& out_dir) {
    require(has_dram, "--dram-trace: this run has no DRAM (ideal_memory)");
    const fs::path dir(out_dir);
    log.write_dramsim3((dir / "dram_trace.dramsim3.txt").string());
    log.write_csv((dir / "dram_requests.csv").string());
    json j = log.summary();
    j["clock_ghz"] = c.clock_ghz;
    j["dram"] = config_to_json(c)["dram"];
    j["dramsim3_bytes_per_transaction"] = DramRequestLog::kDramsim3Bytes;
    j["cycles_are"] = "rtsim core cycles (clock_ghz)";
    std::ofstream((dir / "dram_trace.json").string()) << j.dump(2) << "\n";
}

}  // namespace

LevelResult run_timed_level(RunInputs& in) {
    const RunSetup& s = in.setup;
    const SimConfig& c = s.config;
    // Spill areas belong to contexts, or to rays in treelet mode (they move between units).
    BuiltRun built = build_run(in, c.treelets.enabled);
    Accel& accel = *built.accel;
    const MemoryMap& map = *built.map;
    // Sampling (sim/sampling/sampling.h): only the sample's rays are simulated and checked.
    std::unique_ptr<SampledRun> sampled;
    if (c.sampling.enabled() && !sample_covers_trace(c, built.rays))
        sampled = std::make_unique<SampledRun>(in.reader, c, built.rays, built.frames);
    const uint64_t simulated = sampled ? sampled->plan.simulated_rays : built.rays;
    ReferenceWindow reference(in.reader, c.dispatch.chunk_rays);
    HitChecker checker("checker", sampled ? static_cast<ReferenceSource&>(sampled->reference) : reference, simulated,
                       progress_of(in.options));
    // Any-hit rays in another child order than the trace's: occlusion checked alone, the
    // model's own work timed and counted.
    checker.set_reordered_anyhit(s.step.reorders_anyhit());
    if (s.packet_reference) {
        // Packets change each ray's work: it is checked against the reference packet loop.
        const float split = s.packet_reference->split_below;
        const StepOptions step = s.step.reference_walk();
        checker.set_packet_reference(
            [&accel, split, step](const Ray* r, const TraversalMode* m, uint32_t n, Hit* h, WorkCounts* w) {
                accel.trace_packet(r, m, n, h, w, nullptr, split, step);
            });
    }
    FrameRecorder frame_figures(c, built.frames, in.manifest.value("frames", json(nullptr)));
    Timeline timeline(c.clock_ghz);
    const SimConfig model_config = timed_config(c);
    // The frame (shading.enabled, shading_run.h): the wavefront loop streams bounce by bounce.
    const std::unique_ptr<ShadingInputs> shading = load_shading_inputs(in.reader, c);
    const bool wavefront = shading && c.shading.frame_loop == FrameLoop::wavefront;
    const std::vector<FrameRecord> segments = wavefront ? wavefront_segments(*shading) : built.frames;
    FrameRayStream stream(in.reader, segments);
    Top top("top", model_config, accel, s.step, map, sampled ? static_cast<RayStream&>(sampled->stream) : stream,
            checker, built.features, shading.get());
    // The build unit, where the trace's frames record their builds (frame_builds.h).
    std::vector<std::vector<BuildJob>> build_jobs =
        c.build_unit.enabled ? frame_build_jobs(accel) : std::vector<std::vector<BuildJob>>{};
    if (c.build_unit.overlap) move_to_second_buffer(build_jobs);
    std::unique_ptr<BuildUnit> build_unit;
    if (!build_jobs.empty())
        build_unit = std::make_unique<BuildUnit>(c.build_unit, top.shared_memory(), c.l2.line_bytes);
    // Frame barriers: record each frame's figures, then bind the structure's next frame.
    std::vector<uint64_t> frame_rays;
    for (const FrameRecord& f : segments) frame_rays.push_back(f.rays);
    // Moving scenes (rtl_model/build_unit/build_unit.h): each frame's structures are built at the
    // barrier before its rays (run at once: the units are idle; the frame's figures are taken
    // before the build), or beside the previous frame's rays (build_unit.overlap: streamed in
    // time by a process of its own). build_frame(f, at): the cycle frame f may start, the frame
    // before it having ended at `at`.
    const bool overlap = c.build_unit.overlap && build_unit;
    std::unique_ptr<BuildStreamer> streamer;
    if (overlap) streamer = std::make_unique<BuildStreamer>("build_streamer", *build_unit);
    std::vector<Cycle> build_end(build_jobs.size(), 0);
    auto start_build = [&](uint32_t f, Cycle at) {
        build_end[f] = at;
        if (build_jobs[f].empty()) return;
        if (overlap) return streamer->start(build_jobs[f], at);
        const FrameBuild b = build_unit->run(build_jobs[f], at);
        frame_figures.set_build(f, b);
        build_end[f] = b.end;
    };
    auto finish_build = [&](uint32_t f) {
        if (!overlap || build_jobs[f].empty()) return build_end[f];
        const FrameBuild b = streamer->finish();
        frame_figures.set_build(f, b);
        return build_end[f] = b.end;
    };
    // The wavefront loop builds no frame after the last with rays: an overlapped build must not
    // start one either (it would run beside that frame's rays and never be waited for).
    uint32_t built_frames = uint32_t(build_jobs.size());
    if (wavefront && !shading->wavefront_frame.empty())
        built_frames = std::min(built_frames, shading->wavefront_frame.back() + 1);
    FrameBuildSchedule schedule(overlap, built_frames, start_build, finish_build);
    auto build_frame = [&](uint32_t f, Cycle at) { return schedule.ready(f, at); };
    auto build_at_barrier = [&](uint32_t f, Cycle end) {
        frame_figures.frame_end(f, end, top.memory_totals());
        return build_frame(f + 1, end);
    };
    if (wavefront) {
        // Each bounce's barrier is its shading; a frame's figures at its last bounce, and an
        // animated trace's next frame's structures bound before its first.
        top.dispatch().set_frames(frame_rays, nullptr, [&, bound = -1](uint32_t w) mutable {
            const int f = w < shading->wavefront_frame.size() ? int(shading->wavefront_frame[w]) : 0;
            if (f != bound && built.frames.size() > 1) accel.bind_frame(uint32_t(f));
            bound = f;
        });
        // Frames first..last build their structures one after another from `at` (frame_builds.h).
        FrameBuilds builds;
        if (build_unit)
            builds = [&](uint32_t first, uint32_t last, Cycle at) {
                for (uint32_t f = first; f <= last && f < build_jobs.size(); ++f) at = build_frame(f, at);
                return at;
            };
        // Leading empty frames end at cycle 0, before the first frame with rays, whose structures
        // are built from cycle 0 beside its ray generation.
        const uint32_t first_frame = shading->wavefront_frame.empty() ? 0 : shading->wavefront_frame[0];
        for (uint32_t f = 0; f < first_frame; ++f) frame_figures.frame_end(f, 0, top.memory_totals());
        wire_frame_loop(
            top, c.shading, *shading,
            [&](uint32_t f, Cycle end) { frame_figures.frame_end(f, end, top.memory_totals()); }, builds);
        if (builds && first_frame > 0) {
            const Cycle built = builds(1, first_frame, 0);
            top.dispatch().hold_until(top.shading()->await_build(built));
        }
    } else if (!sampled || built.frames.size() > 1) {
        // A sampled animated trace: each frame's clusters behind its barrier, its structure bound for them.
        // The in-flight frame loop over an animated trace: a frame ends when its last hit is
        // shaded; the next frame's camera rays are generated then, beside its builds.
        const uint32_t first_frame = shading && !shading->wavefront_frame.empty() ? shading->wavefront_frame[0] : 0;
        auto inflight_barrier = [&, first_frame](uint32_t f, Cycle end) {
            ShadingBlock& block = *top.shading();
            const Cycle shaded = f < first_frame ? end : block.end_frame_inflight(end);  // leading empty frames: no rays
            frame_figures.frame_end(f, shaded, top.memory_totals());
            if (f + 1 >= built.frames.size()) return shaded;
            const Cycle built_at = build_frame(f + 1, shaded);
            if (f + 1 < first_frame) return built_at;
            // The first frame with rays had its camera rays generated from cycle 0.
            if (f + 1 == first_frame) return block.await_build(built_at);
            return block.await_build(std::max(built_at, block.begin_frame(f + 1, shaded)));
        };
        if (shading && built.frames.size() > 1) top.dispatch().set_barrier(inflight_barrier);
        else if (build_unit) top.dispatch().set_barrier(build_at_barrier);  // before: leading empty frames build too
        top.dispatch().set_frames(
            sampled ? sampled->plan.rays_per_frame(built.frames.size()) : frame_rays,
            [&](uint32_t f, Cycle end) {
                if (!frame_figures.recorded(f)) frame_figures.frame_end(f, end, top.memory_totals());
            },
            [&](uint32_t f) { accel.bind_frame(f); });
        if (shading) wire_frame_loop(top, c.shading, *shading, nullptr);
    }
    std::unique_ptr<TraceReader> kind_reader;  // outlives the hook (called during sc_start)
    if (in.options.timeline) {
        kind_reader = std::make_unique<TraceReader>(in.rtt);
        checker.on_ray = [&](const RayResult& r) {
            if (r.id < Timeline::kMaxRays) {
                RayRecord rec;
                kind_reader->read(SectionKind::rays, r.id, 1, &rec);
                timeline.ray(r, rec.kind);
            }
        };
    }
    if (sampled)
        checker.on_ray = [&, hook = checker.on_ray](const RayResult& r) {
            sampled->estimator.ray_done(r);
            if (hook) hook(r);
        };
    DramRequestLog dram_log;  // outlives the run (the DRAM writes into it during sc_start)
    if (in.options.dram_trace && top.dram()) top.dram()->record_requests(&dram_log);
    std::unique_ptr<FunctionalWarmer> warmer;  // sampled runs with functional warming
    if (sampled && c.sampling.warming_rays > 0) {
        warmer = std::make_unique<FunctionalWarmer>(
            accel, s.step, step_costs(c, accel.op_kinds()), map, in.reader, c.traversal.units,
            [&top](uint32_t unit, uint64_t addr, uint32_t bytes) { top.warm(unit, addr, bytes); });
        sampled->stream.set_warming(c.sampling.warming_rays, [&](uint64_t first, uint64_t end, uint64_t position) {
            warmer->warm(first, end, uint32_t(position % c.traversal.units));
        });
    }
    try {
        sc_core::sc_start();
    } catch (const sc_core::sc_report& e) {
        // An rtsim::Error raised in a SystemC process (a traversal stack overflow, say): name
        // the trace and the ray instead of SystemC's wrapper (exit 2, not a raw report).
        const std::string ray = first_failing_ray(accel, in.reader);
        throw Error(in.rtt + ": " + (ray.empty() ? "simulation failed: " + unwrap_report(e.what()) : ray));
    }
    require(checker.checked() == simulated, "simulation ended with " + std::to_string(checker.checked()) + " of " +
                                                std::to_string(simulated) + " rays finished");
    LevelResult r;
    r.cycles = top.total_cycles();
    r.model = top.stats_json();
    if (build_unit) {
        r.model["build_unit"] = build_unit->stats_json();
        r.model["build_unit"]["share"] = r.cycles ? double(frame_figures.build_wait_cycles()) / double(r.cycles) : 0.0;
    }
    r.instantiated = top.instantiated();
    if (build_unit)
        r.instantiated.push_back({{"block", "build_unit"}, {"instantiated", true},
                                  {"why", overlap ? "a moving scene: each frame's structures are built or refit beside "
                                                    "the previous frame's rays (build_unit.overlap)"
                                                  : "a moving scene: each frame's structures are built or refit at its barrier"}});
    if (in.options.timeline && top.dram())
        timeline.write((fs::path(in.options.out_dir) / "timeline.json").string(), top.units(),
                       top.dram()->bytes_over_time(), Dram::bucket_cycles());
    if (in.options.dram_trace) write_dram_trace(dram_log, c, top.dram() != nullptr, in.options.out_dir);
    const double wall = in.wall_seconds();
    r.summary = summarize(c, r.cycles, built.rays, r.model,
                          {checker.hit_mismatches(), checker.work_mismatches(), checker.latency().mean()}, wall);
    if (sampled) {
        std::vector<double> tails;
        if (built.frames.size() > 1) {
            // Each frame drains at its barrier, which the strata's steady-state cost leaves out.
            tails = frame_barrier_tails(frame_figures.to_json(), sampled->plan, sampled->estimator, built.frames.size());
            double sum = 0;
            for (double t : tails) sum += t;
            sampled->estimator.set_barrier_cycles(sum);
        }
        apply_sampling_to_summary(r.summary, c, sampled->plan, sampled->estimator);
        if (built.frames.size() > 1) {
            apply_sampling_to_frames(frame_figures.mutable_json(), c, sampled->plan, sampled->estimator, built.frames,
                                     tails);
            // The run's DRAM bytes as the frames': the rays' scaled, the builds' (simulated whole) not.
            double bytes = 0;
            for (const json& f : frame_figures.to_json()) bytes += f.value("dram_bytes", 0.0);
            r.summary["dram_bytes"] = bytes;
            r.summary["dram_bytes_per_ray"] = built.rays ? bytes / double(built.rays) : 0.0;
        }
        r.sampling = sampled->estimator.to_json(c, r.cycles, wall);
        r.sampling["functional_warming"] = {{"rays_per_cluster", c.sampling.warming_rays},
                                            {"warmed_rays", warmer ? warmer->warmed_rays() : 0},
                                            {"warmed_reads", warmer ? warmer->warmed_reads() : 0},
                                            {"seconds", warmer ? warmer->seconds() : 0.0}};
    }
    r.validation = checker.to_json();
    if (top.shading()) {
        // Texel addresses are checked like node fetches: every shaded ray's against the reference.
        r.validation["texel_mismatches"] = top.shading()->texel_mismatches();
        r.validation["shaded_rays"] = top.shading()->shaded();
        r.validation["order_violations"] = top.shading()->order_violations();
        if (top.shading()->texel_mismatches()) r.validation["first_texel_mismatch"] = top.shading()->first_mismatch();
    }
    r.latency = checker.latency().to_json();
    r.workload = built.workload;
    r.frames = frame_figures.to_json();
    r.frame_count = built.frames.size();
    r.work = checker.work_totals();
    r.rays = checker.checked();
    r.bad = checker.hit_mismatches() || checker.work_mismatches() || (top.shading() && (top.shading()->texel_mismatches() || top.shading()->order_violations()));
    // The verdict's estimates trace a sample of rays against the structure (kept alive by the
    // closure, as the report stage runs after this level returns).
    auto kept = std::make_shared<BuiltRun>(std::move(built));
    r.judge = [&in, kept, instantiated = r.instantiated](const json& model) {
        return judge(verdict_context(in, *kept, model, instantiated));
    };
    return r;
}

}  // namespace rtsim
