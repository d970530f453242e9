#include "sim/analytic/analytic.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "rtl_model/common/ray_state.h"
#include "sim/analytic/analysis_cache.h"
#include "sim/analytic/estimate.h"
#include "sim/analytic/round_waits.h"
#include "sim/analytic/sample.h"
#include "sim/sampling/sampling.h"
#include "sim/harness/trace_stream.h"

namespace rtsim {

using nlohmann::json;

namespace {

/// Sums every ray's work record (one streaming pass; each chunk's CRC is checked as it is read).
void work_totals(TraceReader& reader, AnalyticProfile* p) {
    const uint64_t n = reader.section(SectionKind::work).record_count;
    std::vector<WorkRecord> buf(65536);
    p->rays = n;
    p->work.fill(0.0);
    for (uint64_t first = 0; first < n; first += buf.size()) {
        const uint64_t count = std::min<uint64_t>(buf.size(), n - first);
        reader.read(SectionKind::work, first, count, buf.data());
        WorkTotals sums;
        for (uint64_t i = 0; i < count; ++i) {
            const WorkCounts w = buf[i].counts();
            sums.add(w);
            const double steps = plan_step_work(w);
            if (steps > p->longest_ray_steps) p->longest_ray_steps = steps, p->longest_ray_tests = w.tri_tests;
        }
        for (int f = 0; f < kWorkFieldCount; ++f) p->work[size_t(f)] += double(sums.field[size_t(f)]);
    }
}

/// The work the steppers' techniques add to or save from the trace's (mailbox lookups and the
/// tests they skip, restart-trail re-descents, a reduced-precision walk's extra subtrees, an
/// oriented BVH's rotations), which
/// a trace's work records never hold: measured on the stepped sample and scaled to the trace by
/// the ratio of the trace's plan-step work to the sample's (a ratio estimator, as the cache
/// sample's counts are scaled; Cochran 1977, ch. 6). A whole-trace sample scales by 1, exactly.
void extrapolate_stepped_work(AnalyticProfile& p) {
    auto& s = p.sample_work;
    std::array<double, kWorkFieldCount> traced = s;
    traced[size_t(WorkField::tri_tests)] += s[size_t(WorkField::mailbox_hits)];
    for (int f = kTracedWorkFieldCount; f < kWorkFieldCount; ++f) traced[size_t(f)] = 0.0;
    const double sample_steps = AnalyticProfile::plan_step_work(traced);
    if (sample_steps <= 0) return;
    const double r = AnalyticProfile::plan_step_work(p.work) / sample_steps;
    // The TLAS's share is in the trace's steps already; the rest is on top of the trace's walk.
    for (WorkField f : {WorkField::mailbox_lookups, WorkField::mailbox_hits, WorkField::stack_drops,
                        WorkField::restarts, WorkField::restart_steps, WorkField::restart_box_tests,
                        WorkField::rp_box_hits, WorkField::rp_steps, WorkField::rp_box_tests, WorkField::rp_tri_tests,
                        WorkField::obb_rotations})
        p.work[size_t(f)] = s[size_t(f)] * r;
    p.work[size_t(WorkField::tri_tests)] =
        std::max(0.0, p.work[size_t(WorkField::tri_tests)] - p.work[size_t(WorkField::mailbox_hits)]);
}

/// A vector of rays as a stream.
class VectorStream : public RayStream {
public:
    explicit VectorStream(const std::vector<RayJob>& jobs) : m_jobs(jobs) {}
    size_t read_chunk(size_t max, std::vector<RayJob>* out) override {
        const size_t n = std::min(max, m_jobs.size() - m_next);
        out->insert(out->end(), m_jobs.begin() + long(m_next), m_jobs.begin() + long(m_next + n));
        m_next += n;
        return n;
    }
    uint64_t total_rays() const override { return m_jobs.size(); }

private:
    const std::vector<RayJob>& m_jobs;
    size_t m_next = 0;
};

/// Keeps the results of the rays it forwards (for replay) and the longest ray's work.
class RecordingSink : public RaySinkIf {
public:
    explicit RecordingSink(RaySinkIf& next) : m_next(next) {}
    void ray_done(const RayResult& r) override {
        results.push_back(r);
        m_next.ray_done(r);
    }
    std::vector<RayResult> results;

private:
    RaySinkIf& m_next;
};

struct Memo {
    AnalyticProfile profile;
    std::vector<RayResult> results;
};

/// Analyses of ray streams already stepped in this process (the verdict evaluates several
/// configurations on the same sample), by key; a handful at most.
std::map<std::string, Memo>& memo() {
    static std::map<std::string, Memo> m;
    return m;
}

std::string stream_fingerprint(const std::vector<RayJob>& jobs, const Accel& accel, const StepOptions& step) {
    uint64_t h = 1469598103934665603ull;
    auto add = [&](const void* data, size_t n) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
    };
    // The structure by address and by what it is: an address alone is reused once a structure
    // is freed (the verdict opens and closes alternative structures one after another).
    const void* a = &accel;
    add(&a, sizeof a);
    const AccelImage& image = accel.image();
    add(image.kind.data(), image.kind.size());
    const uint64_t sizes[] = {image.footprint_bytes(), image.end_address()};
    add(sizes, sizeof sizes);
    add(&step.mailbox_entries, sizeof step.mailbox_entries);
    add(&step.short_stack_entries, sizeof step.short_stack_entries);
    add(&step.box_precision_bits, sizeof step.box_precision_bits);
    add(&step.anyhit_order, sizeof step.anyhit_order);
    for (const RayJob& j : jobs) {
        add(&j.id, sizeof j.id);
        add(&j.ray, sizeof j.ray);
        add(&j.any_hit, sizeof j.any_hit);
    }
    return std::to_string(h) + ":" + std::to_string(jobs.size());
}

/// The sample's rays stepped in the unit kind's lock-step groups, functionally (warps, packets:
/// UnitKind::group_profile), added to the profile; nothing for kinds whose contexts run alone.
void profile_groups(const SimConfig& c, const Accel& accel, const StepOptions& step, const std::vector<RayJob>& jobs,
                    AnalyticProfile& p) {
    const UnitKind& kind = c.traversal.kind();
    if (!kind.group_profile) return;
    // Each unit's rays as the dispatch deals them (interleaved blocks, the sorting stage): the
    // groups a unit forms are of its own rays.
    VectorStream stream(jobs);
    RayDealer dealer(c.dispatch, c.traversal.units, stream);
    std::vector<std::vector<RayJob>> by_unit(c.traversal.units);
    for (bool dealt = true; dealt;) {
        dealt = false;
        for (uint32_t u = 0; u < c.traversal.units; ++u) {
            RayJob job;
            if (dealer.next_ray(u, &job)) by_unit[u].push_back(job), dealt = true;
        }
    }
    GroupSetup setup;
    setup.line_bytes = c.l1.line_bytes;
    LocalityPartition partition;
    if (c.treelets.enabled && kind.needs.treelet_queues) {
        // The ray buffer's admission, as the sample's (sample.cpp) and the model's.
        const TreeletConfig& t = c.treelets;
        partition = accel.partition(uint64_t(t.treelet_kib) * 1024);
        const uint32_t state = ray_state_bytes(c.traversal.stack_entries, c.traversal.stack_entry_bytes,
                                               c.mailbox.entries * MailboxConfig::kEntryBytes);
        setup.treelets = &partition;
        setup.capacity = std::max<uint64_t>(1, uint64_t(t.buffer_kib) * 1024 / state);
        setup.admit_limit = t.max_rays_in_flight ? t.max_rays_in_flight : setup.capacity + c.traversal.contexts();
        setup.may_overflow = t.max_rays_in_flight != 0;
    }
    // Rounds as time: a group waits for its step's slowest line, judged by its reuse distances.
    auto waits = std::make_shared<LineWaits>(c.traversal.units);
    setup.line_wait = [waits](uint32_t unit, uint64_t line) { return waits->read(unit, line); };
    p.group += kind.group_profile(accel, step, c.traversal, by_unit, setup);
    p.has_group = true;
}

AnalyticOutcome outcome_of(const SimConfig& config, const AnalyticProfile& profile) {
    AnalyticEstimate e = estimate_analytic(config, profile);
    AnalyticOutcome out;
    out.cycles = Cycle(e.form.cycles);
    out.model = std::move(e.model);
    out.instantiated = std::move(e.instantiated);
    return out;
}

}  // namespace

const AnalyticProfile& analyze_stream(const SimConfig& config, const Accel& accel, const MemoryMap& map,
                                      const StepOptions& step, RayStream& rays, RaySinkIf& sink) {
    std::vector<RayJob> jobs;
    while (rays.read_chunk(65536, &jobs)) {
    }
    const std::string key = analysis_key(config, config.analytic, stream_fingerprint(jobs, accel, step)).dump();
    auto& cache = memo();
    auto it = cache.find(key);
    if (it != cache.end()) {
        for (const RayResult& r : it->second.results) sink.ray_done(r);
        return it->second.profile;
    }
    Memo m;
    AnalyticProfile& p = m.profile;
    p.accel_kind = accel.kind();
    p.op_kinds = accel.op_kinds();
    RecordingSink recording(sink);
    SampleProfiler profiler(config, accel, map, step, p);
    VectorStream stream(jobs);
    profiler.run_cluster(stream, 0, ~0ull, recording);
    profiler.finish();
    profile_groups(config, accel, step, jobs, p);
    // The stream is its own sample: its work totals are the stepped rays'; nothing ran before it.
    p.whole_trace = true;
    p.rays = uint64_t(p.sample_rays);
    p.work = p.sample_work;
    for (const RayResult& r : recording.results) {
        const double steps = plan_step_work(r.work);
        if (steps > p.longest_ray_steps) p.longest_ray_steps = steps, p.longest_ray_tests = r.work.tri_tests;
    }
    m.results = std::move(recording.results);
    if (cache.size() >= 8) cache.erase(cache.begin());
    return cache.emplace(key, std::move(m)).first->second.profile;
}

AnalyticOutcome run_analytic(const SimConfig& config, const Accel& accel, const MemoryMap& map,
                             const StepOptions& step, RayStream& rays, RaySinkIf& sink) {
    return outcome_of(config, analyze_stream(config, accel, map, step, rays, sink));
}

SamplePlan analysis_plan(uint64_t rays, const AnalyticConfig& s, const SimConfig& config,
                         const std::vector<FrameRecord>& frames) {
    if (frames.size() > 1) {
        // Clusters must not cross a frame barrier (the structure changes there): one in each of
        // K frames spread evenly, each frame planned as a trace of its own with one cluster.
        SamplePlan plan;
        plan.trace_rays = rays;
        const size_t k = std::max<size_t>(1, std::min<size_t>(s.clusters, frames.size()));
        AnalyticConfig one = s;
        one.clusters = 1;
        for (size_t i = 0; i < k; ++i) {
            const FrameRecord& f = frames[(2 * i + 1) * frames.size() / (2 * k)];
            if (f.rays == 0) continue;
            SamplePlan sub = analysis_plan(f.rays, one, config);
            for (SamplePlan::Cluster c : sub.clusters) {
                c.stratum_first += f.first_ray, c.first += f.first_ray;
                plan.clusters.push_back(c);
                plan.simulated_rays += c.warmup + c.measured;
            }
            plan.warmup_rays = std::max(plan.warmup_rays, sub.warmup_rays);
        }
        return plan;
    }
    SamplePlan plan;
    plan.trace_rays = rays;
    const uint64_t tail = uint64_t(config.traversal.units) * config.traversal.contexts();
    const uint32_t warmup = s.resolved_warmup_rays(config.l2.lines());
    const uint64_t length = uint64_t(warmup) + s.measured_rays + tail;
    const uint64_t clusters = std::min<uint64_t>(s.clusters, length ? rays / length : 0);
    if (rays <= s.whole_trace_rays || clusters == 0) {
        plan.clusters.push_back({0, rays, 0, 0, rays});
    } else {
        // One cluster in the middle of each of K equal strata (deterministic).
        for (uint64_t k = 0; k < clusters; ++k) {
            const uint64_t first = rays * k / clusters, end = rays * (k + 1) / clusters;
            const uint64_t start = first + (end - first - length) / 2;
            plan.clusters.push_back({first, end - first, start, warmup, s.measured_rays + tail});
        }
        plan.warmup_rays = warmup;
    }
    for (const auto& c : plan.clusters) plan.simulated_rays += c.warmup + c.measured;
    return plan;
}

AnalyticProfile analyze_trace(const SimConfig& config, const Accel& accel, const MemoryMap& map,
                              const StepOptions& step, TraceReader& reader, RaySinkIf& sink,
                              const AnalyticConfig& sample, const std::vector<FrameRecord>& frames,
                              const std::function<void(uint32_t)>& bind_frame) {
    const auto t0 = std::chrono::steady_clock::now();
    AnalyticProfile p;
    p.accel_kind = accel.kind();
    p.op_kinds = accel.op_kinds();
    work_totals(reader, &p);
    const SamplePlan plan = analysis_plan(p.rays, sample, config, frames);
    // Every ray stepped and measured: the whole trace (every frame of an animated one).
    uint64_t covered = 0;
    for (const SamplePlan::Cluster& c : plan.clusters)
        if (c.warmup == 0 && c.measured == c.stratum_rays) covered += c.measured;
    const bool whole = covered == p.rays;
    SampleProfiler profiler(config, accel, map, step, p);
    std::vector<RayRecord> buffer;
    for (const SamplePlan::Cluster& c : plan.clusters) {
        if (frames.size() > 1) {  // the frame the cluster lies in
            const auto f = std::upper_bound(frames.begin(), frames.end(), c.first,
                                            [](uint64_t id, const FrameRecord& r) { return id < r.first_ray; });
            bind_frame(uint32_t(f - frames.begin() - 1));
            profiler.begin_frame_sample(uint32_t(f - frames.begin() - 1));
        }
        std::vector<RayJob> jobs;
        read_ray_jobs(reader, c.first, size_t(c.warmup + c.measured), &buffer, &jobs);
        VectorStream stream(jobs);
        const uint64_t measure_first = c.first + c.warmup;
        const bool full = c.warmup == 0 && c.measured == c.stratum_rays;
        const uint64_t measure_end = full ? c.end() : measure_first + sample.measured_rays;
        profiler.run_cluster(stream, measure_first, measure_end, sink);
        profile_groups(config, accel, step, jobs, p);
    }
    profiler.finish();
    extrapolate_stepped_work(p);
    p.whole_trace = whole;
    p.analysis_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return p;
}

}  // namespace rtsim
