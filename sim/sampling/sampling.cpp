#include "sim/sampling/sampling.h"

#include <algorithm>
#include <cmath>

#include "rtl_model/common/ray_state.h"
#include "traces/common/error.h"
#include "traces/common/rng.h"
#include "traces/format/trace_checks.h"

namespace rtsim {

using nlohmann::json;

namespace {

/// Rays the machine's contexts hold at once: what a cluster's warm-up must at least replace.
uint64_t rays_in_flight(const SimConfig& c) { return uint64_t(c.traversal.units) * c.traversal.contexts(); }

/// With treelet scheduling, the rays the ray buffer admits beyond the contexts' (its SRAM's, or
/// treelets.max_rays_in_flight's excess); 0 without. Until the buffer has filled its queues are
/// short and a treelet load serves few rays: a cluster must fill it before it measures, and
/// measure at least as long (docs/fidelity.md, "Sampling with treelets").
uint64_t buffer_rays(const SimConfig& c) {
    if (!c.treelets.enabled) return 0;
    if (c.treelets.max_rays_in_flight) {
        const uint64_t contexts = rays_in_flight(c);
        return c.treelets.max_rays_in_flight > contexts ? c.treelets.max_rays_in_flight - contexts : 0;
    }
    const uint32_t state = ray_state_bytes(c.traversal.stack_entries, c.traversal.stack_entry_bytes,
                                           c.mailbox.entries * MailboxConfig::kEntryBytes);
    return std::max<uint64_t>(1, uint64_t(c.treelets.buffer_kib) * 1024 / std::max<uint32_t>(state, 1));
}

/// The warm-up a cluster wants: the rays in flight twice over (pipelines and L1s), and an eighth
/// of the L2's lines in rays, about what refills the L2's share of the region the cluster is in
/// (measured on Sponza diffuse rays, docs/fidelity.md: less leaves the L2 cold and the estimate
/// several percent high).
uint64_t warmup_target(const SimConfig& c) {
    // Functional warming fills the caches: the simulated warm-up only refills the contexts and
    // pipelines (SMARTS's detailed warming).
    if (c.sampling.warming_rays > 0) return 2 * rays_in_flight(c) + buffer_rays(c);
    const uint64_t l2_lines = c.l2.lines();
    return std::max<uint64_t>(2 * rays_in_flight(c) + buffer_rays(c), c.ideal_memory ? 0 : l2_lines / 8);
}

constexpr uint64_t kMinClusters = 5;  ///< below this the t interval is too wide to be useful
constexpr uint64_t kFewClusters = 10;  ///< below this the sample is flagged as too small

/// Why the estimate of a sample this small should not be trusted (empty: no reason known).
json sample_caveats(const SimConfig& c, const SamplePlan& plan) {
    json out = json::array();
    const size_t k = plan.clusters.size();
    if (k < kFewClusters)
        out.push_back("only " + std::to_string(k) + " clusters: the interval rests on " + std::to_string(k - 1) +
                      " degrees of freedom");
    if (plan.warmup_rays < plan.warmup_target)
        out.push_back("warm-up cut to " + std::to_string(plan.warmup_rays) + " of the " +
                      std::to_string(plan.warmup_target) + " rays wanted per cluster: the estimate is biased high");
    if (k && plan.clusters[0].measured < 4 * rays_in_flight(c) + buffer_rays(c))
        out.push_back("clusters of " + std::to_string(plan.clusters[0].measured) +
                      " measured rays, under 4 x the rays in flight" + (c.treelets.enabled ? " plus the ray buffer's" : "") +
                      ": the estimate may be biased high");
    if (c.sampling.warming_rays == 0 && !c.ideal_memory)
        out.push_back("no functional warming: the caches see only the sampled rays (biased high)");
    return out;
}

}  // namespace

namespace {

/// Moves each cluster into one frame: the part of its stratum within one frame that holds the
/// cluster and contains its random start, else the largest such part.
void fit_clusters_in_frames(SamplePlan& plan, const std::vector<FrameRecord>& frames) {
    for (SamplePlan::Cluster& cl : plan.clusters) {
        const uint64_t size = cl.end() - cl.first, s0 = cl.stratum_first, s1 = cl.stratum_first + cl.stratum_rays;
        int64_t best = -1;
        uint64_t best_rays = 0;
        for (size_t f = 0; f < frames.size(); ++f) {
            const uint64_t a = std::max(s0, frames[f].first_ray), b = std::min(s1, frames[f].first_ray + frames[f].rays);
            if (b <= a || b - a < size) continue;
            if (cl.first >= a && cl.first < b) {  // the random start's part: keep the offset there
                best = int64_t(f), best_rays = ~0ull;
                break;
            }
            if (b - a > best_rays) best = int64_t(f), best_rays = b - a;
        }
        require(best >= 0, "config: sampling: a cluster of " + std::to_string(size) + " rays fits in no frame of its "
                           "stratum (rays " + std::to_string(s0) + " to " + std::to_string(s1) + "); lower "
                           "'sampling.warmup_rays' or raise 'sampling.clusters', or trace more rays per frame");
        const FrameRecord& fr = frames[size_t(best)];
        const uint64_t a = std::max(s0, fr.first_ray), b = std::min(s1, fr.first_ray + fr.rays);
        cl.first = std::min(std::max(cl.first, a), b - size);
        cl.frame = uint32_t(best);
    }
}

}  // namespace

SamplePlan plan_sample(const SimConfig& c, uint64_t n, const std::vector<FrameRecord>& frames) {
    const SamplingConfig& s = c.sampling;
    SamplePlan plan;
    plan.trace_rays = n;
    require(s.count <= n, "config: 'sampling.count' = " + std::to_string(s.count) + " is more than the trace's " +
                              std::to_string(n) + " rays");
    const uint64_t budget = s.count ? s.count : uint64_t(std::llround(s.fraction * double(n)));
    // At least as many measured as warm-up rays per cluster: fewer clusters rather than clusters
    // that are mostly warm-up (their measurement would be mostly pipeline edge effects).
    plan.warmup_target = s.warmup_rays ? s.warmup_rays : warmup_target(c);
    uint64_t w = plan.warmup_target;
    // With functional warming, a cluster measures at least 4 x the rays in flight: fewer, longer
    // clusters. Before the cluster hand-off (SampledRayStream::next_segment) shorter ones (M = 2 x
    // in flight) measured Sponza diffuse about 3% slow; with it, 16 units at K = 7, M = 601 still
    // +3% against +1.4% at K = 5, M = 1046 (docs/fidelity.md, "Cluster hand-off").
    const uint64_t min_measured =
        s.warming_rays > 0 && s.warmup_rays == 0 ? 4 * rays_in_flight(c) + buffer_rays(c) : 0;
    uint64_t clusters = std::min<uint64_t>(s.clusters, budget / (w + std::max(w, min_measured)));
    if (!s.warmup_rays && clusters < kMinClusters) {
        // Too small a sample for full warm-up: keep kMinClusters and shrink the warm-up to half of
        // each cluster, never below 2 x rays in flight (the estimate is then biased high).
        clusters = std::min<uint64_t>(s.clusters, kMinClusters);
        w = std::max<uint64_t>(2 * rays_in_flight(c), budget / (2 * clusters));
        clusters = std::min<uint64_t>(clusters, budget / (2 * w));
    }
    plan.warmup_rays = w;
    require(clusters >= 2, "config: sampling: a sample of " + std::to_string(budget) + " rays is too small for " +
                               "2 clusters of " + std::to_string(plan.warmup_rays) + " warm-up and as many measured " +
                               "rays (need " + std::to_string(4 * plan.warmup_rays) +
                               "); raise 'sampling.fraction' or 'sampling.count', or lower 'sampling.warmup_rays'");
    const uint64_t size = budget / clusters;  // <= n / clusters <= every stratum
    for (uint64_t k = 0; k < clusters; ++k) {
        SamplePlan::Cluster cl;
        cl.stratum_first = k * n / clusters;
        cl.stratum_rays = (k + 1) * n / clusters - cl.stratum_first;
        // A random offset within the stratum (stratified random sampling, one cluster each).
        const uint64_t slack = cl.stratum_rays - size;
        cl.first = cl.stratum_first + hash_combine(s.seed, k, 0x5a3b1e) % (slack + 1);
        cl.warmup = plan.warmup_rays;
        cl.measured = size - plan.warmup_rays;
        plan.clusters.push_back(cl);
    }
    plan.simulated_rays = clusters * size;
    if (frames.size() > 1) {
        fit_clusters_in_frames(plan, frames);
        for (const FrameRecord& f : frames) plan.frame_first.push_back(f.first_ray);
    }
    return plan;
}

bool sample_covers_trace(const SimConfig& c, uint64_t n) {
    const SamplingConfig& s = c.sampling;
    if (s.count > n) return false;  // more rays than the trace: plan_sample says so
    const uint64_t budget = s.count ? s.count : uint64_t(std::llround(s.fraction * double(n)));
    if (budget >= n) return true;
    SimConfig all = c;  // the largest sample: every ray
    all.sampling.count = uint32_t(std::min<uint64_t>(n, INT32_MAX));
    try {
        plan_sample(all, n);
    } catch (const Error&) {
        return true;  // no sample of this trace is possible
    }
    return false;
}

double student_t_975(uint64_t df) {
    // t_{0.975} for df = 1..30 (standard tables), then the Cornish-Fisher expansion in 1/df
    // around the normal quantile, accurate to 1e-4 beyond 30.
    static const double table[] = {12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228,
                                   2.201,  2.179, 2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086,
                                   2.080,  2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042};
    require(df >= 1, "student_t_975: df must be at least 1");
    if (df <= 30) return table[df - 1];
    const double z = 1.959963984540054, d = double(df);
    const double z3 = z * z * z, z5 = z3 * z * z, z7 = z5 * z * z;
    return z + (z3 + z) / (4 * d) + (5 * z5 + 16 * z3 + 3 * z) / (96 * d * d) +
           (3 * z7 + 19 * z5 + 17 * z3 - 15 * z) / (384 * d * d * d);
}

size_t sample_index(const SamplePlan& plan, uint64_t id, size_t* cluster) {
    auto it = std::upper_bound(plan.clusters.begin(), plan.clusters.end(), id,
                               [](uint64_t v, const SamplePlan::Cluster& c) { return v < c.first; });
    require(it != plan.clusters.begin() && id < std::prev(it)->end(),
            "sampling: ray " + std::to_string(id) + " is not in the sample");
    const size_t k = size_t(std::prev(it) - plan.clusters.begin());
    if (cluster) *cluster = k;
    // The clusters before k (of equal sizes, but a per-frame analysis's may differ: analytic.cpp).
    uint64_t before = 0;
    for (size_t j = 0; j < k; ++j) before += plan.clusters[j].warmup + plan.clusters[j].measured;
    return size_t(before + (id - plan.clusters[k].first));
}

SampledRayStream::SampledRayStream(TraceReader& reader, const SamplePlan& plan) : m_reader(reader), m_plan(plan) {
    if (!plan.clusters.empty()) m_next = plan.clusters[0].first;
}

void SampledRayStream::set_warming(uint64_t rays, std::function<void(uint64_t, uint64_t, uint64_t)> warm) {
    m_warming_rays = rays;
    m_warm = std::move(warm);
}

bool SampledRayStream::next_segment() {
    if (m_cluster >= m_plan.clusters.size()) return false;
    if (m_plan.clusters[m_cluster].frame > m_frame) return false;  // after the frame barrier
    m_open_cluster = m_cluster;
    return true;
}

void SampledRayStream::begin_frame(uint32_t f) {
    m_frame = f;
    if (m_cluster < m_plan.clusters.size() && m_plan.clusters[m_cluster].frame <= f) m_open_cluster = m_cluster;
}

size_t SampledRayStream::read_chunk(size_t max, std::vector<RayJob>* out) {
    if (m_cluster >= m_plan.clusters.size() || m_cluster != m_open_cluster) return 0;
    const SamplePlan::Cluster& c = m_plan.clusters[m_cluster];
    if (m_next == c.first && m_warm) {
        // Functional warming of the skipped rays just before the cluster (not into the previous one).
        // Nor into the previous frame, traced through another frame's structures.
        uint64_t floor = m_cluster ? m_plan.clusters[m_cluster - 1].end() : 0;
        if (c.frame < m_plan.frame_first.size()) floor = std::max(floor, m_plan.frame_first[c.frame]);
        const uint64_t from = std::max(floor, c.first - std::min(c.first, m_warming_rays));
        m_warm(from, c.first, m_produced);
    }
    // A chunk never crosses into the next cluster, and the next cluster is read only after
    // next_segment(), so its warming happens once every ray of this one has entered a context.
    const size_t n = size_t(std::min<uint64_t>(max, c.end() - m_next));
    read_ray_jobs(m_reader, m_next, n, &m_buffer, out);
    m_next += n;
    m_produced += n;
    if (m_next == c.end() && ++m_cluster < m_plan.clusters.size()) m_next = m_plan.clusters[m_cluster].first;
    return n;
}

SampledReference::SampledReference(TraceReader& reader, const SamplePlan& plan) : m_reader(reader), m_plan(plan) {
    check_ray_sections(reader);
}

SampledReference::Loaded& SampledReference::loaded_for(uint64_t id) {
    size_t k = 0;
    sample_index(m_plan, id, &k);
    for (Loaded& l : m_loaded)
        if (l.cluster == k) return l;
    const SamplePlan::Cluster& c = m_plan.clusters[k];
    const uint64_t n = c.end() - c.first;
    Loaded l{k, std::vector<HitRecord>(n), std::vector<WorkRecord>(n), n};
    m_reader.read(SectionKind::hits, c.first, n, l.hits.data());
    m_reader.read(SectionKind::work, c.first, n, l.work.data());
    m_loaded.push_back(std::move(l));
    return m_loaded.back();
}

const HitRecord& SampledReference::hit(uint64_t id) {
    Loaded& l = loaded_for(id);
    return l.hits[id - m_plan.clusters[l.cluster].first];
}

const WorkRecord& SampledReference::work(uint64_t id) {
    Loaded& l = loaded_for(id);
    return l.work[id - m_plan.clusters[l.cluster].first];
}

void SampledReference::checked(uint64_t id) {
    Loaded& l = loaded_for(id);
    if (--l.remaining == 0)
        m_loaded.erase(std::find_if(m_loaded.begin(), m_loaded.end(), [&](const Loaded& x) { return &x == &l; }));
}

SampleEstimator::SampleEstimator(const SamplePlan& plan, SampleMeasure measure)
    : m_plan(plan), m_measure(measure), m_start(plan.simulated_rays, 0), m_seen(plan.simulated_rays, 0) {}

void SampleEstimator::ray_done(const RayResult& r) {
    size_t k = 0;
    const size_t i = sample_index(m_plan, r.id, &k);
    m_start[i] = m_measure == SampleMeasure::starts ? r.start : r.end;
    const uint32_t f = m_plan.clusters[k].frame;
    if (f >= m_frame_last_start.size()) m_frame_last_start.resize(f + 1, 0);
    // The measure the strata use (with treelets, completions: the buffer admits rays long before
    // it traces them, so a frame's last admission is not where its drain begins).
    m_frame_last_start[f] = std::max(m_frame_last_start[f], m_start[i]);
    m_seen[i] = 1;
    m_done = false;
}

void SampleEstimator::finish() const {
    if (m_done) return;
    // Every ray's start (or end), sorted: the rays the machine took on (or finished) within a
    // window of cycles.
    std::vector<Cycle> starts(m_start);
    std::sort(starts.begin(), starts.end());
    const size_t per_cluster = size_t(m_plan.warmup_rays + m_plan.clusters[0].measured);
    m_cycles_per_ray.clear();
    std::vector<double> y;  // per stratum: estimated cycles of the whole stratum
    for (size_t k = 0; k < m_plan.clusters.size(); ++k) {
        const SamplePlan::Cluster& c = m_plan.clusters[k];
        const auto first = m_start.begin() + std::ptrdiff_t(k * per_cluster + c.warmup);
        const auto [lo, hi] = std::minmax_element(first, first + std::ptrdiff_t(c.measured));
        // Rays that started (finished) within [first measured start, last measured start], minus
        // one: the number of intervals the window spans (ties at one cycle count as 0-length).
        const size_t started = size_t(std::upper_bound(starts.begin(), starts.end(), *hi) -
                                      std::lower_bound(starts.begin(), starts.end(), *lo));
        const double cpr = started > 1 ? double(*hi - *lo) / double(started - 1) : 0.0;
        m_cycles_per_ray.push_back(cpr);
        y.push_back(cpr * double(c.stratum_rays));
    }
    const double k = double(y.size());
    double sum = 0, sq = 0;
    for (double v : y) sum += v;
    const double mean = sum / k;
    for (double v : y) sq += (v - mean) * (v - mean);
    // The K strata as a sample of K: Var(total) = K s^2 (conservative for stratified sampling:
    // it also counts the variation between strata, which stratification removes).
    m_total = sum;
    m_half = student_t_975(y.size() - 1) * std::sqrt(k * sq / (k - 1));
    m_done = true;
}

double SampleEstimator::cycles() const { return finish(), m_total + m_barrier_cycles; }
double SampleEstimator::ci_low() const { return finish(), std::max(0.0, m_total - m_half) + m_barrier_cycles; }
double SampleEstimator::ci_high() const { return finish(), m_total + m_half + m_barrier_cycles; }

double SampleEstimator::cycles_of(uint64_t first, uint64_t rays) const {
    finish();
    double total = 0;
    for (size_t k = 0; k < m_plan.clusters.size(); ++k) {
        const SamplePlan::Cluster& c = m_plan.clusters[k];
        const uint64_t a = std::max(first, c.stratum_first), b = std::min(first + rays, c.stratum_first + c.stratum_rays);
        if (b > a) total += m_cycles_per_ray[k] * double(b - a);
    }
    return total;
}

json SampleEstimator::to_json(const SimConfig& config, Cycle simulated_cycles, double wall) const {
    finish();
    const double hz = config.clock_ghz * 1e9, n = double(m_plan.trace_rays);
    json strata = json::array();
    for (size_t k = 0; k < m_plan.clusters.size(); ++k) {
        const SamplePlan::Cluster& c = m_plan.clusters[k];
        strata.push_back({{"first_ray", c.stratum_first}, {"rays", c.stratum_rays}, {"cluster_first_ray", c.first},
                          {"cycles_per_ray", m_cycles_per_ray[k]}});
    }
    return {{"clusters", m_plan.clusters.size()},
            {"measured_by", m_measure == SampleMeasure::starts ? "starts" : "completions"},
            {"warmup_rays", m_plan.warmup_rays},
            {"warmup_target_rays", m_plan.warmup_target},
            {"measured_rays", m_plan.clusters[0].measured},
            {"simulated_rays", m_plan.simulated_rays},
            {"trace_rays", m_plan.trace_rays},
            {"fraction", double(m_plan.simulated_rays) / n},
            {"seed", config.sampling.seed},
            {"cycles", cycles()},
            {"cycles_ci95", {ci_low(), ci_high()}},
            {"barrier_cycles", m_barrier_cycles},
            {"relative_half_width", cycles() > 0 ? m_half / cycles() : 0.0},
            {"rays_per_second", cycles() > 0 ? n * hz / cycles() : 0.0},
            {"rays_per_second_ci95", {n * hz / ci_high(), ci_low() > 0 ? n * hz / ci_low() : 0.0}},
            {"simulated_cycles", simulated_cycles},
            {"effective_rays_per_wall_second", wall > 0 ? n / wall : 0.0},
            {"caveats", sample_caveats(config, m_plan)},
            {"strata", strata}};
}

void apply_sampling_to_summary(json& s, const SimConfig& config, const SamplePlan& plan, const SampleEstimator& e) {
    const double hz = config.clock_ghz * 1e9, n = double(plan.trace_rays), sim = double(plan.simulated_rays);
    const double seconds = e.cycles() / hz;
    s["sampled"] = true;
    s["cycles"] = uint64_t(std::llround(e.cycles()));
    s["cycles_ci95"] = {e.ci_low(), e.ci_high()};
    s["seconds"] = seconds;
    s["rays_per_second"] = seconds > 0 ? n / seconds : 0.0;
    s["mrays_per_second"] = seconds > 0 ? n / seconds / 1e6 : 0.0;
    s["rays_per_second_ci95"] = {n * hz / e.ci_high(), e.ci_low() > 0 ? n * hz / e.ci_low() : 0.0};
    // Bytes were measured on the simulated rays (warm-up included): scale per ray to the trace.
    const double bytes = s.value("dram_bytes", 0.0);
    s["dram_bytes_per_ray"] = sim > 0 ? bytes / sim : 0.0;
    s["dram_bytes"] = sim > 0 ? bytes / sim * n : 0.0;
    // Simulator speed: rays actually simulated per wall second (sampling.* has the effective one).
    const double wall = s.value("wall_seconds", 0.0);
    s["simulated_rays_per_wall_second"] = wall > 0 ? sim / wall : 0.0;
}

std::vector<double> frame_barrier_tails(const nlohmann::json& frames, const SamplePlan& plan,
                                        const SampleEstimator& estimator, size_t frame_count) {
    const std::vector<uint64_t> sampled = plan.rays_per_frame(frame_count);
    std::vector<double> tails(frame_count, -1.0);
    double sum = 0;
    int n = 0;
    for (const nlohmann::json& f : frames) {
        const uint32_t i = f["frame"].get<uint32_t>();
        if (i >= frame_count || !sampled[i]) continue;
        const Cycle end = f.value("end_cycle", Cycle(0)), last = estimator.frame_last_start(i);
        tails[i] = end > last ? double(end - last) : 0.0;
        sum += tails[i], ++n;
    }
    for (double& t : tails)
        if (t < 0) t = n ? sum / n : 0.0;  // a frame without a cluster drains like the others
    // The build unit's work before a frame's rays (moving scenes) is simulated in full: what the
    // frame waited for it (all of it at the barrier, what was left beside the previous frame's
    // rays with build_unit.overlap).
    for (const nlohmann::json& f : frames) {
        const uint32_t i = f["frame"].get<uint32_t>();
        if (i < frame_count) tails[i] += f.value("build_wait_cycles", f.value("build_cycles", 0.0));
    }
    return tails;
}

void apply_sampling_to_frames(nlohmann::json& frames, const SimConfig& config, const SamplePlan& plan,
                              const SampleEstimator& estimator, const std::vector<FrameRecord>& table,
                              const std::vector<double>& tails) {
    const std::vector<uint64_t> sampled = plan.rays_per_frame(table.size());
    // The build unit's bytes are the whole build's; the rays' bytes scale with the sample. (Its
    // bytes as it moved them through the L2, an upper bound on its DRAM share.)
    auto build_bytes = [](const nlohmann::json& f) {
        return std::min(f.value("dram_bytes", 0.0), f.value("build_read_bytes", 0.0) + f.value("build_written_bytes", 0.0));
    };
    double all_bytes = 0;
    for (const nlohmann::json& f : frames) all_bytes += f.value("dram_bytes", 0.0) - build_bytes(f);
    const double bytes_per_sampled_ray = plan.simulated_rays ? all_bytes / double(plan.simulated_rays) : 0.0;
    double start = 0;
    for (nlohmann::json& f : frames) {
        const uint32_t i = f["frame"].get<uint32_t>();
        const uint64_t rays = table.at(i).rays;
        const double cycles = estimator.cycles_of(table[i].first_ray, rays) + tails.at(i);
        const double per_ray =
            sampled[i] ? (f.value("dram_bytes", 0.0) - build_bytes(f)) / double(sampled[i]) : bytes_per_sampled_ray;
        f["sampled_rays"] = sampled[i];
        f["start_cycle"] = uint64_t(std::llround(start));
        start += cycles;
        f["end_cycle"] = uint64_t(std::llround(start));
        f["cycles"] = uint64_t(std::llround(cycles));
        f["mrays_per_second"] = cycles > 0 ? double(rays) / (cycles / (config.clock_ghz * 1e9)) / 1e6 : 0.0;
        f["dram_bytes"] = per_ray * double(rays) + build_bytes(f);
        f["dram_bytes_per_ray"] = rays ? f["dram_bytes"].get<double>() / double(rays) : 0.0;
    }
}

const StatBlock& sampling_stats() {
    static const StatBlock block{
        "sampling",
        {
            {"clusters", "clusters", "strata of the trace, one simulated cluster each (K)"},
            {"measured_by", "", "how each cluster's throughput is measured: `starts` (the span of its measured rays' start cycles over the rays started in it) or, with treelet scheduling (whose ray buffer admits rays long before it traces them), `completions` (the span of their end cycles over every sampled ray finished in it)"},
            {"warmup_rays", "rays", "warm-up rays at the start of each cluster: simulated, not measured (W)"},
            {"warmup_target_rays", "rays", "the warm-up wanted (`sampling.warmup_rays` or automatic); more than `warmup_rays` when the sample was too small for it, and then the estimate is biased high"},
            {"measured_rays", "rays", "measured rays per cluster, after its warm-up (M)"},
            {"simulated_rays", "rays", "`clusters x (warmup_rays + measured_rays)`: the rays the model ran and the checker checked"},
            {"trace_rays", "rays", "rays in the trace (= `summary.rays`)"},
            {"fraction", "fraction", "`simulated_rays / trace_rays`"},
            {"seed", "", "`sampling.seed`: picks each cluster's offset in its stratum"},
            {"cycles", "cycles", "the estimate: sum over strata of stratum rays x cycles per ray, plus `barrier_cycles` (unrounded `summary.cycles`)"},
            {"barrier_cycles", "cycles", "an animated trace: what the frame barriers add to the strata's steady-state cost, as the sample saw it: each frame's drain (its end minus its last start; a frame without a cluster takes the others' mean) plus, in moving scenes, the build unit's work before it (simulated whole); 0 for one frame"},
            {"cycles_ci95", "cycles", "`[lo, hi]`: Student t 95% interval over the strata"},
            {"relative_half_width", "fraction", "half the interval over the estimate"},
            {"rays_per_second", "rays/s", "`trace_rays` over the estimated seconds"},
            {"rays_per_second_ci95", "rays/s", "`[lo, hi]` for `rays_per_second`"},
            {"simulated_cycles", "cycles", "cycles the sampled simulation itself ran (all clusters back to back)"},
            {"effective_rays_per_wall_second", "rays/s", "`trace_rays / summary.wall_seconds`: what sampling buys"},
            {"strata", "list", "per stratum: `first_ray`, `rays` (its trace range), `cluster_first_ray` (where its cluster starts), `cycles_per_ray` (measured)"},
            {"caveats", "list", "why this sample is too small to trust, one text each (fewer than 10 clusters; warm-up cut below its target; clusters shorter than twice the rays in flight; no functional warming); empty when none applies. `rtsim-sim` also prints each as a warning"},
            {"functional_warming", "", "`rays_per_cluster` (`sampling.warming_rays`: skipped rays before each cluster replayed through the L1s and L2 without time; 0: none), `warmed_rays` (rays replayed in all), `warmed_reads` (the fetches those rays' steps made, plus one ray record each, all made present in the caches), `seconds` (wall time spent warming, part of `summary.wall_seconds`)"},
        }};
    return block;
}

RTSIM_REGISTER_STAT_BLOCK(sampling_stats)

}  // namespace rtsim
