// The functional level: the reference traversal in a loop, no time; counts and the hit check
// only. Packet kinds trace their rays in trace order `lanes` at a time through the reference
// packet loop, never across frames, so their work is checked as the model's would be.
#include <memory>
#include <vector>

#include "sim/harness/frames.h"
#include "sim/harness/hit_checker.h"
#include "sim/harness/level.h"
#include "sim/harness/trace_stream.h"
#include "sim/report/summary.h"
#include "traces/common/error.h"

namespace rtsim {

namespace {

using nlohmann::json;

/// Rays traced as one packet by the reference packet loop.
class FunctionalPackets {
public:
    FunctionalPackets(const Accel& accel, HitChecker& checker, const PacketReference& packets, const StepOptions& step)
        : m_accel(accel), m_checker(checker), m_lanes(packets.lanes), m_split_below(packets.split_below), m_step(step) {}
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
        m_accel.trace_packet(m_rays.data(), m_modes.data(), n, hits.data(), work.data(), nullptr, m_split_below, m_step);
        for (uint32_t i = 0; i < n; ++i) m_results[i].hit = hits[i], m_results[i].work = work[i];
        m_checker.packet_done(m_results.data(), m_rays.data(), m_modes.data(), n);
        m_results.clear(), m_rays.clear(), m_modes.clear();
    }

private:
    const Accel& m_accel;
    HitChecker& m_checker;
    uint32_t m_lanes;
    float m_split_below;
    StepOptions m_step;
    std::vector<RayResult> m_results;
    std::vector<Ray> m_rays;
    std::vector<TraversalMode> m_modes;
};

/// Every ray of the trace through the reference walk (or packets), frame after frame.
void trace_all(Accel& accel, const StepOptions& step, TraceReader& reader, HitChecker& checker,
               const std::vector<FrameRecord>& frames, FunctionalPackets* packets) {
    TraceRayStream stream(reader);
    std::vector<RayJob> jobs;
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
            const TraversalMode mode = job.any_hit ? TraversalMode::any_hit : TraversalMode::closest_hit;
            try {
                if (packets) {
                    packets->add(job);
                    continue;
                }
                r.hit = accel.trace(job.ray, mode, &r.work, step);
            } catch (const Error& e) {
                throw Error(reader.path() + ": ray " + std::to_string(job.id) + ": " + e.what());
            }
            r.mode = mode;
            checker.ray_done(r);
        }
        jobs.clear();
    }
    if (packets) packets->flush();
}

}  // namespace

LevelResult run_functional_level(RunInputs& in) {
    BuiltRun built = build_run(in, false);
    const RunSetup& s = in.setup;
    ReferenceWindow reference(in.reader, s.config.dispatch.chunk_rays);
    HitChecker checker("checker", reference, built.rays, progress_of(in.options));
    // Any-hit rays in another child order than the trace's: occlusion checked alone.
    checker.set_reordered_anyhit(s.step.reorders_anyhit());
    std::unique_ptr<FunctionalPackets> packets;
    if (s.packet_reference) {
        // Packets change each ray's work: it is checked against the reference packet loop.
        const PacketReference p = *s.packet_reference;
        const StepOptions step = s.step.reference_walk();
        Accel& accel = *built.accel;
        checker.set_packet_reference(
            [&accel, p, step](const Ray* r, const TraversalMode* m, uint32_t n, Hit* h, WorkCounts* w) {
                accel.trace_packet(r, m, n, h, w, nullptr, p.split_below, step);
            });
        packets = std::make_unique<FunctionalPackets>(accel, checker, p, step);
    }
    trace_all(*built.accel, s.step, in.reader, checker, built.frames, packets.get());
    require(checker.checked() == built.rays, "simulation ended with " + std::to_string(checker.checked()) + " of " +
                                                 std::to_string(built.rays) + " rays finished");
    FrameRecorder frame_figures(s.config, built.frames, in.manifest.value("frames", json(nullptr)));
    frame_figures.untimed();
    LevelResult r;
    r.model = nullptr;  // no model ran
    r.summary = summarize(s.config, 0, built.rays, r.model,
                          {checker.hit_mismatches(), checker.work_mismatches(), checker.latency().mean()},
                          in.wall_seconds());
    r.validation = checker.to_json();
    r.latency = checker.latency().to_json();
    r.workload = built.workload;
    r.frames = frame_figures.to_json();
    r.frame_count = built.frames.size();
    r.work = checker.work_totals();
    r.rays = checker.checked();
    r.bad = checker.hit_mismatches() || checker.work_mismatches();
    return r;  // no verdict: nothing is timed
}

}  // namespace rtsim
