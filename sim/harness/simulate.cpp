#include "sim/harness/simulate.h"
#include "sim/harness/structure_defaults.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include "rtl_model/top/top.h"
#include "sim/analytic/analytic.h"
#include "sim/report/energy_area.h"
#include "sim/harness/frames.h"
#include "sim/harness/hit_checker.h"
#include "sim/report/roofline.h"
#include "sim/harness/run_files.h"
#include "sim/report/mailbox_stats.h"
#include "sim/report/short_stack_stats.h"
#include "sim/report/box_precision_stats.h"
#include "sim/report/two_level_stats.h"
#include "sim/harness/memory_estimate.h"
#include "sim/harness/model_errors.h"
#include "sim/sampling/sampling.h"
#include "sim/sampling/warming.h"
#include "sim/report/summary.h"
#include "sim/report/stats_schema.h"
#include "sim/report/summary_schema.h"
#include "sim/report/timeline.h"
#include "sim/harness/trace_stream.h"
#include "sim/report/verdict.h"
#include "sim/harness/verdict_check.h"
#include "traces/accel/accel_io.h"
#include "traces/common/error.h"

namespace rtsim {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

void report_progress(uint64_t done, uint64_t total) {
    std::cerr << "{\"progress\": " << done << ", \"total\": " << total << "}" << std::endl;
}

/// Rays traced as one packet by the reference packet loop (functional level, traversal.model packet).
class FunctionalPackets {
public:
    FunctionalPackets(const Accel& accel, HitChecker& checker, uint32_t lanes, float split_below)
        : m_accel(accel), m_checker(checker), m_lanes(lanes), m_split_below(split_below) {}
    void add(const RayJob& job) {
        m_results.push_back(RayResult{});
        m_results.back().id = job.id;
        m_rays.push_back(job.ray);
        m_modes.push_back(job.any_hit ? TraversalMode::any_hit : TraversalMode::closest_hit);
        if (m_rays.size() == m_lanes) flush();
    }
    void flush() {
        const uint32_t n = uint32_t(m_rays.size());
        if (n == 0) return;
        std::vector<Hit> hits(n);
        std::vector<WorkCounts> work(n);
        m_accel.trace_packet(m_rays.data(), m_modes.data(), n, hits.data(), work.data(), nullptr, m_split_below);
        for (uint32_t i = 0; i < n; ++i) m_results[i].hit = hits[i], m_results[i].work = work[i];
        m_checker.packet_done(m_results.data(), m_rays.data(), m_modes.data(), n);
        m_results.clear(), m_rays.clear(), m_modes.clear();
    }

private:
    const Accel& m_accel;
    HitChecker& m_checker;
    uint32_t m_lanes;
    float m_split_below;
    std::vector<RayResult> m_results;
    std::vector<Ray> m_rays;
    std::vector<TraversalMode> m_modes;
};

/// Functional level: the reference traversal in a loop, no time. Counts and the hit check only.
/// With packets (`packets` not null), rays in trace order `lanes` at a time, never across frames.
json run_functional(Accel& accel, TraceReader& reader, HitChecker& checker, const std::vector<FrameRecord>& frames,
                    FunctionalPackets* packets) {
    const std::string& path = reader.path();
    TraceRayStream stream(reader);
    std::vector<RayJob> jobs;
    // A short stack's restarts are counted by the steppers; the fused reference loops walk a full one.
    // So is a reduced-precision box pipeline's extra walk.
    const bool shadows = accel.short_stack_entries() || accel.box_precision_bits();
    const std::unique_ptr<Stepper> stepper = shadows ? accel.make_stepper() : nullptr;
    uint32_t frame = 0;
    accel.bind_frame(0);
    while (stream.read_chunk(65536, &jobs)) {
        for (const RayJob& job : jobs) {
            while (job.id >= frames[frame].first_ray + frames[frame].rays) {
                if (packets) packets->flush();
                accel.bind_frame(++frame);
            }
            RayResult r;
            r.id = job.id;
            try {
                if (packets) {
                    packets->add(job);
                    continue;
                }
                const TraversalMode mode = job.any_hit ? TraversalMode::any_hit : TraversalMode::closest_hit;
                r.hit = stepper ? trace_with_stepper(*stepper, job.ray, mode, &r.work) : accel.trace(job.ray, mode, &r.work);
            } catch (const Error& e) {
                throw Error(path + ": ray " + std::to_string(job.id) + ": " + e.what());
            }
            checker.ray_done(r);
        }
        jobs.clear();
    }
    if (packets) packets->flush();
    return json::object();
}


}  // namespace

SimOutcome run_simulation(const SimOptions& options) {
    const SimOptions o = with_structure_defaults(options);  // the structure's stack entry size
    // The analytic level works from a per-trace analysis and a closed form (sim/analytic/analytic.h).
    if (o.config.fidelity == Fidelity::analytic) return run_analytic_simulation(o);
    auto t0 = std::chrono::steady_clock::now();
    const std::time_t started = std::time(nullptr);
    validate(o.config);
    const std::string rtt = trace_file(o.trace);
    TraceReader reader(rtt);
    const json manifest = read_manifest(rtt);
    // The acceleration structure, whichever it is, validated structurally (load_accel).
    const std::unique_ptr<Accel> accel = load_accel(read_accel_image(reader), rtt);
    apply_mailbox(*accel, o.config);
    apply_short_stack(*accel, o.config);
    apply_box_precision(*accel, o.config);
    // Animated traces (frames.h): replayed frame after frame, caches warm, one barrier between.
    const std::vector<FrameRecord> frames = read_frame_table(reader, accel->frame_count());
    check_frames_supported(o.config, frames.size(), rtt);
    FrameRecorder frame_figures(o.config, frames, manifest.value("frames", json(nullptr)));
    check_sim_memory(o.config, accel->image().footprint_bytes(),
                     "config (traversal.units=" + std::to_string(o.config.traversal.units) +
                         ", traversal.ray_contexts=" + std::to_string(o.config.traversal.ray_contexts) + ")");
    WorkloadFeatures features;
    json workload = scan_workload(reader, &features);
    // Check every chunk's CRC now (one streaming pass): the reference window reads HITS and WORK
    // during sc_start, where a corrupt chunk would surface as a SystemC report (exit 1) instead
    // of an error naming the file (exit 2).
    reader.verify_all();
    const uint64_t total = workload["rays"];
    // Sampling (sim/sampling/sampling.h): only the sample's rays are simulated and checked.
    std::unique_ptr<SampledRun> sampled;
    if (o.config.sampling.enabled() && !sample_covers_trace(o.config, total))
        sampled = std::make_unique<SampledRun>(reader, o.config, total);
    const uint64_t simulated = sampled ? sampled->plan.simulated_rays : total;
    // Spill areas belong to contexts, or to rays in treelet mode (they move between units).
    const TraversalConfig& tc = o.config.traversal;
    const MemoryMap map(accel->image().end_address(), total,
                        o.config.treelets.enabled ? total : uint64_t(tc.units) * tc.ray_contexts,
                        accel->max_stack_entries(), tc.stack_entry_bytes);

    fs::create_directories(o.out_dir);
    write_json(fs::path(o.out_dir) / "config.resolved.json", config_to_json(o.config));
    ReferenceWindow reference(reader, o.config.dispatch.chunk_rays);
    HitChecker checker("checker", sampled ? static_cast<ReferenceSource&>(sampled->reference) : reference, simulated,
                       o.progress ? HitChecker::Progress(report_progress) : HitChecker::Progress());

    json model, instantiated = json::array();
    std::unique_ptr<FunctionalWarmer> warmer;  // sampled runs with functional warming
    Cycle cycles = 0;
    std::vector<uint8_t> kinds;  // only for the timeline
    Timeline timeline(o.config.clock_ghz);
    // Detailed: units synchronise every cycle (quantum 1), so shared blocks see requests in time
    // order (docs/model.md, "The detailed level"); the resolved config keeps the user's value.
    SimConfig timed_config = o.config;
    if (o.config.fidelity == Fidelity::detailed) timed_config.quantum_cycles = 1;
    // Approx with treelets: a shorter quantum (treelets.quantum_cycles; docs/fidelity.md).
    else if (o.config.treelets.enabled)
        timed_config.quantum_cycles = std::min(timed_config.quantum_cycles, o.config.treelets.quantum_cycles);
    std::unique_ptr<FunctionalPackets> packets;
    if (tc.model == UnitModel::packet) {
        // Packets change each ray's work: it is checked against the reference packet loop.
        require(accel->make_packet_stepper() != nullptr,
                "config: 'traversal.model' packet needs a structure with a packet kernel (bvh2); this trace's "
                "structure is '" + accel->kind() + "'");
        const float split = float(tc.packet_split_below);
        checker.set_packet_reference([&accel, split](const Ray* r, const TraversalMode* m, uint32_t n, Hit* h,
                                                     WorkCounts* w) { accel->trace_packet(r, m, n, h, w, nullptr, split); });
        packets = std::make_unique<FunctionalPackets>(*accel, checker, tc.lanes, split);
    }
    if (o.config.fidelity == Fidelity::functional) {
        run_functional(*accel, reader, checker, frames, packets.get());
        frame_figures.untimed();
    } else {
        FrameRayStream stream(reader, frames);
        Top top("top", timed_config, *accel, map, sampled ? static_cast<RayStream&>(sampled->stream) : stream, checker,
                features);
        // Frame barriers: record each frame's figures, then bind the structure's next frame.
        std::vector<uint64_t> frame_rays;
        for (const FrameRecord& f : frames) frame_rays.push_back(f.rays);
        if (!sampled)
            top.dispatch().set_frames(
                frame_rays, [&](uint32_t f, Cycle end) { frame_figures.frame_end(f, end, top.memory_totals()); },
                [&](uint32_t f) { accel->bind_frame(f); });
        std::unique_ptr<TraceReader> kind_reader;  // outlives the hook (called during sc_start)
        if (o.timeline) {
            kind_reader = std::make_unique<TraceReader>(rtt);
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
        if (sampled && o.config.sampling.warming_rays > 0) {
            warmer = std::make_unique<FunctionalWarmer>(
                *accel, step_costs(o.config, accel->op_kinds()), map, reader, tc.units,
                [&top](uint32_t unit, uint64_t addr, uint32_t bytes) { top.warm(unit, addr, bytes); });
            sampled->stream.set_warming(o.config.sampling.warming_rays,
                                        [&](uint64_t first, uint64_t end, uint64_t position) {
                                            warmer->warm(first, end, uint32_t(position % tc.units));
                                        });
        }
        try {
            sc_core::sc_start();
        } catch (const sc_core::sc_report& e) {
            // An rtsim::Error raised in a SystemC process (a traversal stack overflow, say): name
            // the trace and the ray instead of SystemC's wrapper (exit 2, not a raw report).
            const std::string ray = first_failing_ray(*accel, reader);
            throw Error(rtt + ": " + (ray.empty() ? "simulation failed: " + unwrap_report(e.what()) : ray));
        }
        cycles = top.total_cycles();
        model = top.stats_json();
        instantiated = top.instantiated();
        if (o.timeline && top.dram())
            timeline.write((fs::path(o.out_dir) / "timeline.json").string(), top.units(), top.dram()->bytes_over_time(),
                           Dram::bucket_cycles());
    }
    require(checker.checked() == simulated, "simulation ended with " + std::to_string(checker.checked()) + " of " +
                                                std::to_string(simulated) + " rays finished");
    double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    SimOutcome out;
    out.stats = {{"schema", "rtsim-stats/1"},
                 {"fidelity", kFidelityChoices.name(o.config.fidelity)},
                 {"summary", summarize(o.config, cycles, total, model, checker, wall)},
                 {"validation", checker.to_json()},
                 {"latency", checker.latency().to_json()},
                 {"workload", workload},
                 {"instantiated", instantiated},
                 {"effects", manifest.value("workload", json::object()).value("effects", json::array())},
                 {"frames", frame_figures.to_json()},
                 {"model", model},
                 {"provenance", provenance(o.command_line, rtt, manifest, started)}};
    out.stats["summary"]["sampled"] = bool(sampled);
    out.stats["summary"]["frames"] = frames.size();
    if (sampled) {
        apply_sampling_to_summary(out.stats["summary"], o.config, sampled->plan, sampled->estimator);
        out.stats["sampling"] = sampled->estimator.to_json(o.config, cycles, wall);
        out.stats["sampling"]["functional_warming"] = {
            {"rays_per_cluster", o.config.sampling.warming_rays},
            {"warmed_rays", warmer ? warmer->warmed_rays() : 0},
            {"warmed_reads", warmer ? warmer->warmed_reads() : 0},
            {"seconds", warmer ? warmer->seconds() : 0.0}};
    }
    // Energy and area from the run's counts and config (docs/energy_area.md); the timed model
    // never sees them.
    add_mailbox_stats(out.stats, o.config, checker.work_totals(), checker.checked());
    add_short_stack_stats(out.stats, o.config, checker.work_totals(), checker.checked());
    add_box_precision_stats(out.stats, o.config, checker.work_totals(), checker.checked());
    if (accel->kind() == "two_level") add_two_level_stats(out.stats, checker.work_totals(), checker.checked());
    add_energy_area(out.stats, o.config, checker.work_totals(), checker.checked());
    out.stats["roofline"] = roofline_json(o.config, out.stats["summary"], model);
    json verdict = nullptr;
    if (o.verdict && o.config.fidelity != Fidelity::functional && total > 0) {
        // The estimates trace a sample of rays against one bound structure: an animated trace's
        // first frame, its rays against its structure.
        VerdictContext v{o.config, model, accel.get(), &map, &reader};
        v.trace_path = rtt;
        v.instantiated = instantiated;
        v.frames = frames.size();
        if (frames.size() > 1) {
            accel->bind_frame(0);
            v.first_ray = frames[0].first_ray;
            v.frame_rays = frames[0].rays;
        }
        verdict = judge(v);
        if (o.check_verdict) {
            verdict["check"] = check_verdict(o, verdict, out.stats["summary"].value("rays_per_second", 0.0));
            verdict["text"] = checked_text(verdict);
        }
    }
    out.stats["verdict"] = verdict;
    out.stats["summary"]["bottleneck"] = verdict.is_null() ? json(nullptr) : verdict["binding"];
    out.stats["summary"]["verdict"] = verdict.is_null() ? json(nullptr) : verdict["text"];
    check_run_stats(out.stats, bool(sampled));  // every key declared once, by its producer (stats_schema.h)
    write_json(fs::path(o.out_dir) / "stats.json", out.stats);
    write_json(fs::path(o.out_dir) / "provenance.json", out.stats["provenance"]);
    out.exit_code = (checker.hit_mismatches() || checker.work_mismatches()) ? 3 : 0;
    return out;
}

}  // namespace rtsim
