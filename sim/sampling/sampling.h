#pragma once
// Statistical sampling of a trace (sampling.fraction or sampling.count): simulate a stratified
// sample of rays and estimate the full run's cycles with a 95% confidence interval, in the spirit
// of SMARTS (Wunderlich et al., ISCA 2003). docs/fidelity.md explains the design and its bias.
//
// The trace (in trace order: wavefront / pixel order) is split into K equal strata. From each
// stratum one cluster of consecutive rays at a random offset is simulated: W warm-up rays (detailed
// warming: simulated, caches and pipelines warm up, not measured) then M measured rays. All
// clusters run back to back in one simulation through a SampledRayStream; ray ids stay the
// trace's, so the hit checker checks every simulated ray. A cluster's rays (and its functional
// warming) reach the dispatch only once it has handed out every ray of the cluster before, so
// the machine stays full across the switch and the next cluster's warming comes after the last
// ray of the cluster was handed out (in dispatch order; at approx a unit up to a quantum behind
// in simulated time may still start one of them after it). Each cluster's steady-state cost in
// cycles per ray is measured from the start cycles of its measured rays (rays enter contexts in
// dispatch order as contexts free up, so the span of the measured rays' starts over the number of
// rays started in it is the machine's throughput while it worked on that stratum, with the fill
// of the pipeline excluded by the warm-up rays before). The total is the sum over strata of stratum size x cycles per ray; the interval is
// Student t over the K strata. Functional warming (warming.h) fills the caches before
// each cluster; docs/fidelity.md measures the bias.
#include <cstdint>
#include <deque>
#include <functional>
#include <vector>

#include <nlohmann/json.hpp>

#include "rtl_model/common/stats.h"
#include "rtl_model/common/interfaces.h"
#include "rtl_model/dispatch/dispatch.h"
#include "sim/config/config.h"
#include "sim/harness/trace_stream.h"
#include "traces/format/trace_reader.h"

namespace rtsim {

/// Which rays a sampled run simulates.
struct SamplePlan {
    struct Cluster {
        uint64_t stratum_first = 0;  ///< first ray of the stratum (trace index)
        uint64_t stratum_rays = 0;   ///< rays in the stratum (what the cluster stands for)
        uint64_t first = 0;          ///< first ray of the cluster (its first warm-up ray)
        uint64_t warmup = 0;         ///< warm-up rays, [first, first + warmup)
        uint64_t measured = 0;       ///< measured rays, [first + warmup, first + warmup + measured)
        uint32_t frame = 0;          ///< the frame its rays belong to (an animated trace)
        uint64_t end() const { return first + warmup + measured; }
    };
    uint64_t trace_rays = 0;
    uint64_t simulated_rays = 0;  ///< warm-up and measured rays of all clusters
    uint64_t warmup_rays = 0;     ///< per cluster (the resolved sampling.warmup_rays)
    uint64_t warmup_target = 0;   ///< what the cluster wanted (more than warmup_rays if the sample is small)
    std::vector<Cluster> clusters;  ///< in trace order
    std::vector<uint64_t> frame_first;  ///< an animated trace: each frame's first ray (else empty)

    /// The rays the sample simulates in each of `frames` frames (its clusters', by their frame).
    std::vector<uint64_t> rays_per_frame(size_t frames) const {
        std::vector<uint64_t> out(frames, 0);
        for (const Cluster& c : clusters) out.at(c.frame) += c.end() - c.first;
        return out;
    }
};

/// The plan for a trace of `trace_rays` rays; throws rtsim::Error naming the sampling field when
/// the trace is too small for the requested clusters and warm-up. With the frames of an animated
/// trace each cluster lies in one frame (the part of its stratum in one frame that holds it and
/// its random start, else the largest part that holds it: a stratum still stands for all its
/// rays), so a frame's structure is bound for it alone.
SamplePlan plan_sample(const SimConfig& config, uint64_t trace_rays, const std::vector<FrameRecord>& frames = {});

/// True when sampling would simulate the whole trace anyway: the sample asked for is every ray
/// (sampling.fraction = 1, a count of exactly the trace's rays), or the trace is smaller than
/// the smallest sample (2 clusters of warm-up and measured rays). The run is then simply not
/// sampled: exact. A count above the trace's rays stays an error (plan_sample).
bool sample_covers_trace(const SimConfig& config, uint64_t trace_rays);

/// The Student t quantile t_{0.975, df}: the half-width factor of a two-sided 95% interval.
double student_t_975(uint64_t df);

/// Feeds only the clusters' rays, in trace order, to the dispatch.
class SampledRayStream : public RayStream {
public:
    SampledRayStream(TraceReader& reader, const SamplePlan& plan);
    size_t read_chunk(size_t max, std::vector<RayJob>* out) override;
    uint64_t total_rays() const override { return m_plan.simulated_rays; }
    /// Before each cluster's first ray is read, calls warm(first, end, position) on up to `rays`
    /// skipped rays just before it; position: how many rays the stream produced before it
    /// (warming.h).
    void set_warming(uint64_t rays, std::function<void(uint64_t first, uint64_t end, uint64_t position)> warm);
    /// Each cluster is a segment (RayStream::next_segment): its reads end at its last ray, and the
    /// next cluster's first read, where its functional warming runs, waits until the dispatch has
    /// handed out every ray of this one. Else the warming would replace the caches' lines under
    /// the cluster's last measured rays while some still wait in the dispatch's per-unit queues
    /// (docs/fidelity.md, "Cluster hand-off").
    bool next_segment() override;
    /// An animated trace: the clusters of frame f may be read (the dispatch's frame barrier
    /// calls this once frame f - 1's rays have finished and its structure is bound).
    void begin_frame(uint32_t f) override;

private:
    TraceReader& m_reader;
    const SamplePlan& m_plan;
    uint64_t m_warming_rays = 0;
    std::function<void(uint64_t, uint64_t, uint64_t)> m_warm;
    uint64_t m_produced = 0;  ///< rays returned so far
    size_t m_cluster = 0;       ///< the cluster being read (clusters.size() at the end)
    size_t m_open_cluster = 0;  ///< the cluster the dispatch may read (next_segment opens the next)
    uint32_t m_frame = 0;       ///< the frame being handed out (clusters of later frames wait)
    uint64_t m_next = 0;  ///< next trace index within the current cluster
    std::vector<RayRecord> m_buffer;
};

/// Reference hits and work of the sampled rays, loaded one cluster at a time and dropped when all
/// of a cluster's rays are checked (memory: the clusters with rays in flight).
class SampledReference : public ReferenceSource {
public:
    SampledReference(TraceReader& reader, const SamplePlan& plan);
    const HitRecord& hit(uint64_t id) override;
    const WorkRecord& work(uint64_t id) override;
    void checked(uint64_t id) override;

private:
    struct Loaded {
        size_t cluster;
        std::vector<HitRecord> hits;
        std::vector<WorkRecord> work;
        uint64_t remaining;
    };
    Loaded& loaded_for(uint64_t id);

    TraceReader& m_reader;
    const SamplePlan& m_plan;
    std::deque<Loaded> m_loaded;

};

/// How a cluster's throughput is measured. starts: the span of its measured rays' start cycles
/// over the rays the machine started in it (rays enter contexts as contexts free up). With
/// treelet scheduling the ray buffer admits rays long before the machine traces them, so starts
/// measure admission, not work: completions then measures the span of the measured rays' end
/// cycles over every sampled ray the machine finished in it (any cluster's: the machine's
/// completion rate while it worked on the stratum, clusters overlapping in the buffer).
enum class SampleMeasure : uint8_t { starts, completions };

/// Records each simulated ray's start and end cycles and turns them into the estimate.
class SampleEstimator {
public:
    SampleEstimator(const SamplePlan& plan, SampleMeasure measure);
    void ray_done(const RayResult& r);
    /// stats.json "sampling": the estimate, its interval and the per-stratum measurements.
    nlohmann::json to_json(const SimConfig& config, Cycle simulated_cycles, double wall_seconds) const;
    /// Estimated total cycles and its 95% interval.
    double cycles() const;
    double ci_low() const;
    double ci_high() const;
    /// Estimated cycles of trace rays [first, first + rays): each stratum's cycles per ray over
    /// its rays in that range (the frames of an animated trace sum to cycles()).
    double cycles_of(uint64_t first, uint64_t rays) const;
    /// An animated trace: each frame's last start (any sampled ray's; its last completion when
    /// the strata measure completions), by cluster frame.
    Cycle frame_last_start(uint32_t f) const { return f < m_frame_last_start.size() ? m_frame_last_start[f] : 0; }
    /// Cycles the frame barriers add on top of the strata's steady-state throughput (each
    /// frame drains before the next begins): added to cycles() and its interval.
    void set_barrier_cycles(double cycles) { m_barrier_cycles = cycles; }

private:
    void finish() const;

    const SamplePlan& m_plan;
    SampleMeasure m_measure;
    std::vector<Cycle> m_start;  ///< per simulated ray, in sample order (starts or ends: m_measure)
    std::vector<uint8_t> m_seen;
    mutable bool m_done = false;
    mutable std::vector<double> m_cycles_per_ray;  ///< per cluster
    mutable double m_total = 0, m_half = 0;
    std::vector<Cycle> m_frame_last_start;
    double m_barrier_cycles = 0;
};

/// Index of the sample position of trace ray `id` (clusters in order); throws if not sampled.
size_t sample_index(const SamplePlan& plan, uint64_t id, size_t* cluster = nullptr);

/// Everything a sampled run adds to the harness: the plan, the stream that feeds the model, the
/// reference the hit checker reads and the estimator that records start cycles.
struct SampledRun {
    SampledRun(TraceReader& reader, const SimConfig& config, uint64_t trace_rays,
               const std::vector<FrameRecord>& frames = {})
        : plan(plan_sample(config, trace_rays, frames)),
          stream(reader, plan),
          reference(reader, plan),
          estimator(plan, config.treelets.enabled ? SampleMeasure::completions : SampleMeasure::starts) {}
    SamplePlan plan;
    SampledRayStream stream;
    SampledReference reference;
    SampleEstimator estimator;
};

/// Overwrites the summary's run-wide keys with the sampled estimate: cycles, seconds, rays/s
/// (for the whole trace), cycles_ci95, rays_per_second_ci95, dram_bytes (scaled), sampled.
void apply_sampling_to_summary(nlohmann::json& summary, const SimConfig& config, const SamplePlan& plan,
                               const SampleEstimator& estimator);

/// A sampled animated run's stats.json "frames": each frame's figures as the barriers recorded
/// them for its sampled rays (`sampled_rays`), its cycles and rays/s replaced by the estimate
/// for all its rays (cycles_of plus its barrier tail), and its DRAM bytes scaled from its sampled rays' (from the
/// whole sample's for a frame without a cluster).
/// Each frame's drain at its barrier, from the sampled run: the frame's end minus its last
/// start (a frame without a cluster: the mean of the others).
std::vector<double> frame_barrier_tails(const nlohmann::json& frames, const SamplePlan& plan,
                                        const SampleEstimator& estimator, size_t frame_count);
void apply_sampling_to_frames(nlohmann::json& frames, const SimConfig& config, const SamplePlan& plan,
                              const SampleEstimator& estimator, const std::vector<FrameRecord>& table,
                              const std::vector<double>& tails);

/// stats.json "sampling" (sampled runs only), declared once.
const StatBlock& sampling_stats();

}  // namespace rtsim
