#include "sim/analytic/estimate.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>

#include "rtl_model/dispatch/dispatch.h"
#include "rtl_model/mem/mem_stats.h"
#include "rtl_model/traversal/traversal_unit.h"
#include "sim/analytic/reuse.h"

namespace rtsim {

using nlohmann::json;

/// Miss probabilities per reuse bin of one cache shape (lines, ways) on one stream's curve,
/// each computed on first use.
class LevelMisses {
public:
    LevelMisses(const ReuseCurve& curve, double lines, uint32_t ways, bool cold)
        : m_curve(curve), m_lines(lines), m_ways(ways), m_cold(cold), m_table(2 * DistanceBins::kBins, -1.0) {}
    bool is(double lines, uint32_t ways) const { return lines == m_lines && ways == m_ways; }
    double operator()(int b, bool censored) {
        double& m = m_table[size_t(2 * b + censored)];
        if (m < 0) m = bin_miss_probability(m_curve, b, censored, m_lines, m_ways, m_cold);
        return m;
    }

private:
    const ReuseCurve& m_curve;
    double m_lines;
    uint32_t m_ways;
    bool m_cold;  ///< censored accesses are compulsory misses (whole-trace analysis)
    std::vector<double> m_table;
};

/// A profile's reuse curves and the miss tables of every cache shape asked for so far: one
/// configuration's evaluation computes its L1's and L2's tables; evaluating many against one
/// profile (the verdict's knobs and pairs) reuses them wherever the cache shape is unchanged.
class MissModel {
public:
    explicit MissModel(const AnalyticProfile& p)
        : m_unit(p.unit_events, p.unit_censored), m_global(p.global_events, p.global_censored), m_cold(p.whole_trace) {}
    LevelMisses& l1(const CacheConfig& c) { return table(m_l1, m_unit, c); }
    LevelMisses& l2(const CacheConfig& c) { return table(m_l2, m_global, c); }

private:
    LevelMisses& table(std::deque<LevelMisses>& tables, const ReuseCurve& curve, const CacheConfig& c) {
        const double lines = double(c.size_kib) * 1024.0 / c.line_bytes;
        for (LevelMisses& t : tables)
            if (t.is(lines, c.ways)) return t;
        return tables.emplace_back(curve, lines, c.ways, m_cold);
    }
    ReuseCurve m_unit, m_global;
    bool m_cold;
    std::deque<LevelMisses> m_l1, m_l2;  ///< a deque: references stay valid as tables are added
};

namespace {

/// Miss probabilities per reuse bin for one configuration's L1 and L2.
class MissTables {
public:
    MissTables(const SimConfig& c, MissModel& model)
        : m_ideal(c.ideal_memory), m_l1(model.l1(c.l1)), m_l2(model.l2(c.l2)) {}
    /// P(L1 miss) and P(L1 miss and L2 miss) of an access in a joint cell.
    std::pair<double, double> cell(uint32_t key) const {
        if (m_ideal) return {0.0, 0.0};
        int ub, gb;
        bool uc, gc;
        JointHistogram::unpack(key, &ub, &uc, &gb, &gc);
        const double p1 = m_l1(ub, uc);
        return {p1, p1 * m_l2(gb, gc)};
    }

private:
    bool m_ideal;
    LevelMisses& m_l1;
    LevelMisses& m_l2;
};

/// Whole-trace counts of one data kind.
struct KindCounts {
    double reads = 0, read_bytes = 0, l1_misses = 0, l2_misses = 0, writes = 0, write_bytes = 0;
};

json counters_json(double reads, double writes, double hits, double read_bytes, double write_bytes) {
    return {{"reads", reads},         {"writes", writes},           {"read_hits", hits},
            {"merged", 0.0},          {"hit_rate", reads > 0 ? hits / reads : 0.0},
            {"read_bytes", read_bytes}, {"write_bytes", write_bytes}};
}

class Estimator {
public:
    Estimator(const SimConfig& c, const AnalyticProfile& p, MissModel& misses) : m_c(c), m_p(p), m_miss(c, misses) {
        group_factors();
        const double line = c.l1.line_bytes;
        const double ic = c.interconnect_latency;
        m_lat_l1 = c.l1.latency;
        m_lat_l2 = double(c.l1.latency) + 2.0 * ic + c.l2.latency;
        m_dram = double(c.dram.latency) + std::ceil(line / c.dram.bytes_per_cycle);
        m_lat_dram = m_lat_l2 + m_dram;
    }
    /// The demands and the closed form (all the verdict needs).
    ClosedForm form();
    /// The form and the model's stats as the SystemC model writes them.
    AnalyticEstimate run();
    PredictedRates rates();

private:
    /// Whole trace over sample of what a data kind's accesses happen per (kDataKinds).
    double aux(DataKind kind, bool sample) const {
        const DataKindInfo& k = kDataKinds[size_t(kind)];
        if (k.per_ray) return sample ? m_p.sample_rays : double(m_p.rays);
        return sample ? m_p.sample_work[size_t(k.per_work)] : m_p.work[size_t(k.per_work)];
    }
    /// Whole trace over sample for a data kind's accesses (ratio estimator).
    double scale(DataKind kind) const {
        if (aux(kind, true) > 0) return aux(kind, false) / aux(kind, true);
        return m_p.sample_rays > 0 ? double(m_p.rays) / m_p.sample_rays : 0.0;
    }
    double plan_steps() const {
        const double x1 = AnalyticProfile::plan_step_work(m_p.work) * m_step_scale;
        const double x2 = m_p.work[size_t(WorkField::tri_tests)] * m_work_scale[size_t(WorkField::tri_tests)] +
                          m_p.work[size_t(WorkField::sphere_tests)] * m_work_scale[size_t(WorkField::sphere_tests)] +
                          m_p.work[size_t(WorkField::capsule_tests)] * m_work_scale[size_t(WorkField::capsule_tests)];
        const double fit = m_p.plan_steps_per[0] * x1 + m_p.plan_steps_per[1] * x2;
        if (fit > 0) return fit;
        return m_p.sample_rays > 0 ? m_step_scale * m_p.sample_plan_steps * double(m_p.rays) / m_p.sample_rays : 0.0;
    }
    /// Lock-step kinds (warps, packets): what their groups do differently, from the profile's
    /// functional group stepping (profile.h): the rays' share of the group steps they take part
    /// in (SIMD efficiency), reads per read asked for after coalescing, and the groups' work
    /// against the rays walked alone (a packet's walk tests boxes for rays the node does not
    /// serve). Contexts running alone: 1, 1, 1.
    void group_factors() {
        m_work_scale.fill(1.0);
        if (!m_p.has_group) return;
        const GroupProfile& g = m_p.group;
        if (g.lane_slots > 0 && g.active_lanes > 0) m_active = g.active_lanes / g.lane_slots;
        if (g.lane_requests > 0) m_coalesce = g.requests / g.lane_requests;
        for (size_t f = 0; f < m_work_scale.size(); ++f)
            if (g.single_work[f] > 0) m_work_scale[f] = g.work[f] / g.single_work[f];
        double steps = 0, single = 0;
        for (size_t f = 0; f < m_work_scale.size(); ++f)
            if (kWorkFields[f].plan_step) steps += g.work[f], single += g.single_work[f];
        if (single > 0) m_step_scale = steps / single;
    }
    /// The data a structure's step reads (what a warp coalesces, a packet fetches once).
    static bool structure_data(DataKind kind) {
        return kind == DataKind::node || kind == DataKind::triangle || kind == DataKind::prim_ref ||
               kind == DataKind::cell || kind == DataKind::instance;
    }
    /// Expected slowest of `n` independent accesses drawn from a histogram's (a warp step waits
    /// for the slowest of its lanes' reads): E[max] over the three unloaded latencies. With
    /// `coalesce` < 1 the accesses are fewer than the rays' but their misses as many (the reads a
    /// group merges are the rays' hits on each other's lines): each miss share grows by 1 / coalesce.
    double max_latency(const JointHistogram& h, double n, double coalesce) const {
        double total = 0, at[3] = {0, 0, 0};  // mass at the L1, L2 and DRAM latencies
        for (const auto& [key, count] : h.cells) {
            const auto [m1, m12] = m_miss.cell(key);
            at[0] += count * (1.0 - m1), at[1] += count * (m1 - m12), at[2] += count * m12;
            total += count;
        }
        if (total <= 0) return m_lat_l1;
        at[2] = std::min(total, at[2] / coalesce);
        at[1] = std::min(total - at[2], at[1] / coalesce);
        // (Rounding can leave the L1's share a hair below 0, and a negative base to a fractional
        // power is NaN: a packet of 16 over a BIH had NaN cycles from it.)
        at[0] = std::max(0.0, total - at[1] - at[2]);
        const double lat[3] = {m_lat_l1, m_lat_l2, m_lat_dram};
        double below = 0, e = 0;
        for (int i = 0; i < 3; ++i) {
            const double upto = std::min(1.0, below + at[i] / total);
            e += lat[i] * (std::pow(upto, n) - std::pow(below, n));
            below = upto;
        }
        return e;
    }
    /// Mean unloaded latency of the accesses of a histogram (their slowest lines).
    double mean_latency(const JointHistogram& h) const {
        double n = 0, sum = 0;
        for (const auto& [key, count] : h.cells) {
            const auto [m1, m12] = m_miss.cell(key);
            sum += count * ((1.0 - m1) * m_lat_l1 + (m1 - m12) * m_lat_l2 + m12 * m_lat_dram);
            n += count;
        }
        return n > 0 ? sum / n : m_lat_l1;
    }
    /// The mean wait per planned step a step-critical read adds when it arrives while its line's
    /// earlier miss is still in flight (merged misses: the reuse model calls it a hit). The run's
    /// first read missed with its key's probabilities; the fill is due that miss's unloaded
    /// latency after it, and the read came `gap` accesses later, at the stream's rate of reads
    /// over `cycles` (the unit's for the L1, all units' for the L2).
    /// ... and `*convoy`, the contexts a fill releases at once: its first read's and the merged
    /// ones that wait for it (1 + waiting merged reads over step-critical L1 misses).
    double merge_wait(double cycles, double* convoy) const {
        *convoy = 1.0;
        const double steps = m_p.step_critical.total();
        if (m_c.ideal_memory || steps <= 0 || cycles <= 0) return 0;
        double waiting = 0;  // step-critical reads that wait for a fill in flight (L1 merges)
        double reads = 0;
        for (const KindCounts& kc : m_kinds) reads += kc.reads;
        const double l1_rate = reads / m_c.traversal.units / cycles, l2_rate = reads / cycles;
        double wait = 0;
        for (const auto& [k, n] : m_p.merge_l1) {  // an L1 hit on a line whose fill is due
            uint32_t read_key, head_key;
            int gap_bin;
            MergeKey::unpack(k, &read_key, &head_key, &gap_bin);
            const auto [r1, r12] = m_miss.cell(read_key);
            const auto [h1, h12] = m_miss.cell(head_key);
            const double t = gap_cycles(gap_bin, l1_rate);
            wait += n * (1.0 - r1) *
                    ((h1 - h12) * std::max(0.0, m_lat_l2 - m_lat_l1 - t) + h12 * std::max(0.0, m_lat_dram - m_lat_l1 - t));
            waiting += n * (1.0 - r1) * ((h1 - h12) * (t < m_lat_l2 - m_lat_l1) + h12 * (t < m_lat_dram - m_lat_l1));
        }
        double misses = 0;
        for (const auto& [key, n] : m_p.step_critical.cells) misses += n * m_miss.cell(key).first;
        if (misses > 0) *convoy = 1.0 + waiting / misses;
        for (const auto& [k, n] : m_p.merge_l2) {  // an L2 hit on a line whose DRAM fill is due
            uint32_t read_key, head_key;
            int gap_bin;
            MergeKey::unpack(k, &read_key, &head_key, &gap_bin);
            const auto [r1, r12] = m_miss.cell(read_key);
            const double h12 = m_miss.cell(head_key).second;
            wait += n * (r1 - r12) * h12 * std::max(0.0, m_lat_dram - m_lat_l2 - gap_cycles(gap_bin, l2_rate));
        }
        return wait / steps;
    }
    /// Cycles spanned by a gap in distance bin `b` of a stream read at `rate` lines per cycle.
    static double gap_cycles(int b, double rate) {
        return rate > 0 ? std::sqrt(DistanceBins::low(b) * DistanceBins::high(b)) / rate : 0.0;
    }
    void count_kinds();
    void ops(double* op_latency);
    /// The windows of a whole-trace analysis's rounds as shares of the run (profile.h's
    /// PhaseWindow, or a lock-step kind's GroupWindow), once per estimate; none for sampled
    /// analyses or a machine other than the analysed one. Then
    /// their latencies at the current latency per step.
    void phase_windows();
    void group_phase_windows();
    const std::vector<PhaseShare>& phase_shares(double steps);
    json memory_json(double cycles) const;

    const SimConfig& m_c;
    const AnalyticProfile& m_p;
    MissTables m_miss;
    double m_lat_l1, m_lat_l2, m_lat_dram, m_dram;
    std::vector<PhaseShare> m_phases;   ///< phase_windows()
    std::vector<double> m_phase_fetch;  ///< each window's latency per step over the run's mean
    /// A lock-step kind's ray takes part in this share of its group's steps (active over occupied
    /// lanes): the longest ray's steps over it are its group's.
    double m_longest_share = 1.0;
    double m_group_fetch = 0, m_group_ops = 0;  ///< a lock-step kind's group step: its slowest line, its operations
    std::vector<double> m_phase_contexts;  ///< contexts' windows: the contexts active per unit
    double m_convoy = 1.0;                 ///< contexts a fill releases at once (merge_wait)
    double m_active = 1.0;    ///< SIMD efficiency of a lock-step kind's groups (group_factors)
    double m_coalesce = 1.0;  ///< structure reads after coalescing per read asked for
    double m_step_scale = 1.0;  ///< the groups' plan steps per the rays' own
    std::array<double, kWorkFieldCount> m_work_scale{};  ///< the groups' work per field per the rays' own
    std::array<KindCounts, kDataKindCount> m_kinds;
    AnalyticDemands m_d;
    double m_tests[kOpKindCount] = {};
};

void Estimator::count_kinds() {
    for (int k = 0; k < kDataKindCount; ++k) {
        KindCounts& kc = m_kinds[size_t(k)];
        const JointHistogram& h = m_p.reads[size_t(k)];
        const double s = scale(DataKind(k));
        double n = 0, m1 = 0, m12 = 0;
        for (const auto& [key, count] : h.cells) {
            const auto [a, b] = m_miss.cell(key);
            n += count, m1 += count * a, m12 += count * b;
        }
        kc.reads = n * s;
        kc.read_bytes = m_p.read_bytes[size_t(k)] * s;
        kc.l1_misses = m1 * s;
        kc.l2_misses = m12 * s;
        kc.writes = m_p.writes[size_t(k)] * s;
        kc.write_bytes = m_p.write_bytes[size_t(k)] * s;
    }
}

/// Pipeline issues per kind (each operation of n tests takes ceil(n / width) issues), from the
/// sample's operation sizes scaled by the trace's test counts; returns their unloaded latency.
void Estimator::ops(double* op_latency) {
    *op_latency = 0;
    for (OpKind kind : m_p.op_kinds) {
        const PipelineConfig& pc = m_c.pipeline(kind);
        const size_t k = size_t(kind);
        double tests = 0, issues = 0, latency = 0;
        for (const auto& [n, f] : m_p.op_sizes[k]) {
            const double i = issues_for(n, pc.width);
            tests += f * n, issues += f * i;
            if (i > 0) latency += f * ((i - 1) * pc.initiation_interval + pc.latency);
        }
        const double total = m_p.work[size_t(work_field_of(kind))] * m_work_scale[size_t(work_field_of(kind))];
        const double s = tests > 0 ? total / tests : 0.0;
        m_d.issues[k] = tests > 0 ? issues * s : std::ceil(total / pc.width);
        m_tests[k] = total;
        *op_latency += latency * s;
    }
}

ClosedForm Estimator::form() {
    count_kinds();
    double op_latency = 0;
    ops(&op_latency);
    const double rays = double(m_p.rays), steps = plan_steps();
    m_d.rays = rays;
    m_d.scheduler_steps = rays * kSchedulerSlotsPerRay + steps * kSchedulerSlotsPerStep;
    // A lock-step kind's scheduler takes a group's steps, not each ray's.
    if (m_p.has_group && m_p.group.rays > 0) m_d.scheduler_steps = m_p.group.scheduler_steps * rays / m_p.group.rays;
    for (int k = 0; k < kDataKindCount; ++k) {
        const KindCounts& kc = m_kinds[size_t(k)];
        m_d.l1_accesses += kc.reads * (structure_data(DataKind(k)) ? m_coalesce : 1.0) + kc.writes;
        m_d.l2_accesses += kc.l1_misses + kc.writes;
        m_d.dram_bytes += kc.l2_misses * m_c.l1.line_bytes + kc.write_bytes;
        m_d.l1_hold += kc.l1_misses * (m_lat_l2 - m_lat_l1) + kc.l2_misses * m_dram;
        m_d.l2_hold += kc.l2_misses * m_dram;
    }
    if (m_c.ideal_memory) m_d.l1_accesses = m_d.l2_accesses = m_d.dram_bytes = m_d.l1_hold = m_d.l2_hold = 0;
    double buffer_latency = 0;  // per take from the ray buffer (treelet scheduling)
    if (m_c.treelets.enabled && m_p.sample_rays > 0) {
        // Each take reads a ray's state from the buffer's SRAM and each park writes one (its one
        // port: bandwidth, then latency); a state beyond the SRAM overflows to DRAM and back.
        const TreeletConfig& t = m_c.treelets;
        const double per = rays / m_p.sample_rays;
        const double state = ray_state_bytes(m_c.traversal.stack_entries, m_c.traversal.stack_entry_bytes,
                                             m_c.mailbox.entries * MailboxConfig::kEntryBytes);
        const double takes = m_p.treelet_takes * per, parks = m_p.treelet_parks * per;
        m_d.ray_buffer_bytes = (takes + parks + rays) * state;  // admitted rays are written once too
        const double overflow = m_p.treelet_overflows * per * state * 2;
        m_d.dram_bytes += overflow;
        buffer_latency = t.latency + std::ceil(state / t.bytes_per_cycle);
        m_d.latency_sum_extra = takes * buffer_latency;
        // The step that finds its ray leaving the treelet is a scheduler slot of its own (the
        // context parks the ray and takes the next, whose first step is another). A lock-step
        // kind's group profile has its parks in its group steps already.
        if (!m_p.has_group) m_d.scheduler_steps += parks;
    }
    const double ray_start = m_c.dispatch.latency + mean_latency(m_p.ray_critical);
    const double fetch = mean_latency(m_p.step_critical);
    m_d.latency_sum = rays * ray_start + steps * fetch + op_latency + m_d.latency_sum_extra;
    if (m_p.has_group && m_p.group.group_steps > 0 && steps > 0) {
        // A lock-step group (warp, packet) holds its rays for every group step: the rays'
        // residence is the group's slots times its steps' time. A group step waits for the
        // slowest of its rays' distinct reads (a packet's one fetch, a warp's coalesced lines)
        // and runs its rays' operations one after another on the unit's pipelines.
        const GroupProfile& g = m_p.group;
        const double groups = g.group_steps * rays / g.rays;  // group steps over the whole trace
        const double slots = g.lane_slots / g.group_steps, active = g.active_lanes / g.group_steps;
        // A group step runs one operation kind for its rays (a warp's, a packet's node or leaf):
        // that pipeline's latency and its rays' issues one after another.
        double group_ops = 0, kind_steps = 0;
        for (OpKind kind : m_p.op_kinds) {
            const double n = g.kind_steps[size_t(kind)] * rays / g.rays;  // over the whole trace
            if (n <= 0) continue;
            const PipelineConfig& pc = m_c.pipeline(kind);
            const double issues = m_d.issues[size_t(kind)] / n;  // per group step of this kind
            group_ops += n * (pc.latency + std::max(0.0, issues - 1.0) * pc.initiation_interval);
            kind_steps += n;
        }
        group_ops = kind_steps > 0 ? group_ops / groups : op_latency / steps;
        const double group_fetch = max_latency(m_p.step_critical, std::max(1.0, active * m_coalesce), m_coalesce);
        // With treelet queues the steps that take rays read their states from the ray buffer
        // (its SRAM's latency, for the warp's slowest) instead of the memory: the takes' time.
        const double buffer_steps = m_c.treelets.enabled ? g.buffer_steps * rays / g.rays : 0.0;
        const double fetches = (groups - buffer_steps) * group_fetch + buffer_steps * buffer_latency;
        m_group_fetch = group_fetch, m_group_ops = group_ops;
        // The rays' residence is the lanes holding a ray: fewer than the slots where rays run out
        // (a short trace's drain, a warp waiting for its longest ray).
        const double held = g.occupied_lanes > 0 ? g.occupied_lanes / g.group_steps : slots;
        m_d.latency_sum = rays * ray_start + held * (fetches + groups * group_ops);
        m_d.group_rays = held;
        m_longest_share = held > 0 ? std::min(1.0, active / held) : 1.0;
        // The groups circulate, one visit per group step, each with what its rays' steps ask.
        m_d.customers = double(m_c.traversal.contexts()) / slots;
        m_d.visits = groups;
    }
    // The longest ray: its planned steps at the mean cost of a step.
    const double per_step = steps > 0 ? (steps * fetch + op_latency) / steps : 0.0;
    const double longest = m_p.plan_steps_per[0] * m_p.longest_ray_steps + m_p.plan_steps_per[1] * m_p.longest_ray_tests;
    m_d.latency_max = ray_start + longest * per_step / m_longest_share;
    phase_windows();
    ClosedForm f = closed_form(m_c, m_p.op_kinds, m_d, phase_shares(steps));
    if (!m_p.has_group && (!m_p.merge_l1.empty() || !m_p.merge_l2.empty())) {
        // The merged reads' wait depends on the rate of reads, hence on the cycles it adds to:
        // a fixed point, which a few rounds reach (more wait, fewer reads per cycle, less wait).
        const double base = m_d.latency_sum;
        for (int round = 0; round < 4; ++round) {
            // The reads' rate in the steady state (the phases' fill and drain are not where merges
            // crowd), so steady_cycles does not depend on the phases.
            double convoy = 1.0;
            m_d.merge_wait = merge_wait(f.steady_cycles, &convoy);
            convoy = std::clamp(convoy, 1.0, double(m_c.traversal.contexts()));
            m_convoy = round == 0 ? convoy : 0.5 * (m_convoy + convoy);  // damped: convoys and cycles pull apart
            m_d.latency_sum = base + steps * m_d.merge_wait;
            // Convoys: the contexts one fill releases step on together, so the machine holds
            // fewer independent customers (contexts over the convoy's size), each carrying that
            // many rays through the queues at once. With treelets a unit's contexts walk one
            // treelet and merge on its lines; this is the scheduler's burst that `detailed` waits
            // out and a closed network of independent contexts does not (docs/fidelity.md).
            m_d.convoy = m_convoy;
            const bool convoys = m_convoy > 1.0;
            m_d.customers = convoys ? double(m_c.traversal.contexts()) / m_convoy : 0.0;
            m_d.visits = convoys ? rays / m_convoy : 0.0;
            m_d.group_rays = convoys ? m_convoy : 0.0;
            f = closed_form(m_c, m_p.op_kinds, m_d, phase_shares(steps));
        }
    }
    return f;
}

// Each window of rounds as a run of its own (closed_form's phases): its share of every demand
// (a resource's spread by what drives it in the window: L2 misses for the DRAM and the L2's MSHRs,
// L1 misses for the L1's MSHRs and the L2's banks, line reads for the L1's banks, steps for the
// pipelines and the scheduler), its steps' unloaded latency (their slowest lines') and the
// contexts active in it. At the start every ray is at the top of the tree, its lines in the
// caches, and the DRAM waits; at the end fewer rays than contexts remain and the longest runs
// alone: a closed form over the whole run's totals averages both away. In a steady state every
// window is alike and their sum is the whole run's (docs/fidelity.md, "Where designs starve or
// fill slowly").
void Estimator::phase_windows() {
    m_phases.clear();
    m_phase_fetch.clear();
    m_phase_contexts.clear();
    // The windows' rounds and populations are the analysed machine's: another count of units or
    // contexts (a verdict's knob evaluated on this analysis) would run other rounds.
    if (m_p.phase_units != m_c.traversal.units || m_p.phase_contexts != m_c.traversal.contexts()) return;
    if (m_p.has_group) return group_phase_windows();
    if (m_p.phases.empty()) return;
    PhaseShare all;
    double fetch_sum = 0;
    for (const PhaseWindow& pw : m_p.phases) {
        PhaseShare& s = m_phases.emplace_back();
        for (const auto& [key, count] : pw.reads.cells) {
            const auto [m1, m12] = m_miss.cell(key);
            s.l1_misses += count * m1, s.l2_misses += count * m12, s.reads += count;
        }
        s.steps = s.work = pw.steps;
        s.population = pw.rounds > 0 ? pw.contexts / pw.rounds / m_c.traversal.units : 0.0;
        m_phase_contexts.push_back(s.population);
        const double fetch = mean_latency(pw.critical);
        m_phase_fetch.push_back(fetch);
        fetch_sum += fetch * pw.steps;
        all.steps += s.steps, all.l1_misses += s.l1_misses, all.l2_misses += s.l2_misses, all.reads += s.reads;
    }
    auto share = [](double part, double whole) { return whole > 0 ? part / whole : 0.0; };
    for (PhaseShare& s : m_phases) {
        s.steps = s.work = share(s.steps, all.steps), s.reads = share(s.reads, all.reads);
        s.l1_misses = share(s.l1_misses, all.l1_misses), s.l2_misses = share(s.l2_misses, all.l2_misses);
    }
    // The windows' latencies relative to the run's mean (their octave keys' bias cancels).
    const double mean = all.steps > 0 ? fetch_sum / all.steps : 0.0;
    for (double& f : m_phase_fetch) f = mean > 0 ? f / mean : 1.0;
}

// A lock-step kind's windows come from its functional group stepping (GroupWindow): its memory
// demands are spread by the window's active lanes (each lane's reads), its visits by its group
// steps, its population is the groups holding rays per round and unit (stepping, or waiting for
// a line: rounds as time). Its latency is its group steps at the window's own group-step time:
// the run's, scaled by where the window's slowest lines were served against the run's (the
// drain's warps hold the rays whose lines miss), or without those counts the slowest of its
// active lanes' lines. The fill's cache-warm top of the tree is not in them; the drain is.
// Whole-trace analyses only, without treelet queues.
void Estimator::group_phase_windows() {
    const std::vector<GroupWindow>& windows = m_p.group.phases;
    if (!m_p.whole_trace || m_c.treelets.enabled || windows.empty()) return;
    double steps = 0, lanes = 0;
    for (const GroupWindow& w : windows) steps += w.group_steps, lanes += w.active_lanes;
    if (steps <= 0 || lanes <= 0) return;
    // Where each window's group steps found their slowest line (rounds as time: the L1, the L2,
    // DRAM, judged at the default machine's caches), at this config's latencies.
    const double lat[3] = {m_lat_l1, m_lat_l2, m_lat_dram};
    auto served_latency = [&](const std::array<double, 3>& served) {
        double n = 0, sum = 0;
        for (int i = 0; i < 3; ++i) n += served[size_t(i)], sum += served[size_t(i)] * lat[i];
        return n > 0 ? sum / n : 0.0;
    };
    std::array<double, 3> all{};
    for (const GroupWindow& w : windows)
        for (size_t i = 0; i < all.size(); ++i) all[i] += w.served[i];
    const double run_served = served_latency(all);
    for (const GroupWindow& w : windows) {
        PhaseShare& s = m_phases.emplace_back();
        s.steps = w.group_steps / steps;
        s.work = s.l1_misses = s.l2_misses = s.reads = w.active_lanes / lanes;
        // The groups holding rays per round and unit, those waiting for a line included.
        s.population = w.rounds > 0 ? w.groups / w.rounds / m_c.traversal.units : 0.0;
        // A group step waits for the slowest of its active lanes' lines: fewer lanes, a
        // shorter wait (the drain's warps step with a lane or two).
        const double active = w.group_steps > 0 ? w.active_lanes / w.group_steps : 1.0;
        const double served = served_latency(w.served);
        const double fetch = run_served > 0 && served > 0
                                 ? m_group_fetch * served / run_served
                                 : max_latency(m_p.step_critical, std::max(1.0, active * m_coalesce), m_coalesce);
        const double base = m_group_fetch + m_group_ops;
        m_phase_fetch.push_back(base > 0 ? (fetch + m_group_ops) / base : 1.0);
    }
}

const std::vector<PhaseShare>& Estimator::phase_shares(double steps) {
    if (m_phases.empty() || steps <= 0) return m_phases;
    if (m_p.has_group) {
        for (size_t w = 0; w < m_phases.size(); ++w)
            m_phases[w].latency_sum = m_phases[w].steps * m_d.latency_sum * m_phase_fetch[w];
        return m_phases;
    }
    const double fetch = mean_latency(m_p.step_critical);
    const double other = std::max(0.0, (m_d.latency_sum - steps * fetch) / steps);  // per step: operations, ray starts
    for (size_t w = 0; w < m_phases.size(); ++w) {
        m_phases[w].latency_sum = m_phases[w].steps * steps * (fetch * m_phase_fetch[w] + other);
        m_phases[w].population = m_phase_contexts[w] / m_convoy;  // convoys, as the whole run's
    }
    return m_phases;
}

AnalyticEstimate Estimator::run() {
    AnalyticEstimate e;
    e.form = form();
    e.demands = m_d;
    const double rays = m_d.rays;
    e.mean_latency = rays > 0 ? m_d.latency_sum / rays : 0.0;
    const double units = m_c.traversal.units;
    const std::vector<double> none(kOpKindCount, 0.0);
    std::vector<std::vector<double>> unit_issues(m_c.traversal.units, none), unit_tests(m_c.traversal.units, none);
    for (size_t u = 0; u < unit_issues.size(); ++u)
        for (int k = 0; k < kOpKindCount; ++k) unit_issues[u][k] = m_d.issues[k] / units, unit_tests[u][k] = m_tests[k] / units;
    json& m = e.model;
    m = pipelines_json(m_c, m_p.op_kinds, unit_issues, unit_tests, e.form.cycles);
    StatsWriter(dispatch_stats(), m["dispatch"])  // chunks and steals: not estimated
        .set("rays", rays)
        .set("policy", kDispatchPolicyChoices.name(m_c.dispatch.policy))
        .set("chunk_rays", m_c.dispatch.chunk_rays)
        .set("chunks", nullptr)
        .set("steals", nullptr)
        .done();
    json unit;  // every unit the average unit
    StatsWriter uw(unit_stats_of(m_c.traversal.model), unit);
    uw.set("rays", rays / units)
        .set("steps", m_d.scheduler_steps / units)
        .set("stack_spill_writes", m_p.spill_writes * scale(DataKind::stack) / units)
        .set("stack_spill_reads", m_p.spill_reads * scale(DataKind::stack) / units)
        .set("rejected_rays", nullptr);
    if (m_p.has_group && m_p.group.rays > 0) {  // a lock-step kind's groups, from the profile
        const double s = rays / m_p.group.rays / units;
        uw.set("lane_slots", m_p.group.lane_slots * s).set("active_lanes", m_p.group.active_lanes * s);
        uw.set("simd_efficiency", m_active);
    }
    uw.untimed().done();
    for (uint32_t u = 0; u < m_c.traversal.units; ++u) m["units"]["tu" + std::to_string(u)] = unit;
    json memory = memory_json(e.form.cycles);
    for (auto& [k, v] : memory.items()) m[k] = std::move(v);
    StatsWriter(analytic_stats(), m["analytic"]).merge(closed_form_json(e.form, m_d));
    e.instantiated = analytic_instantiated(m_c, m_p.accel_kind, m_p.op_kinds,
                                           "statistical L1s and L2 (reuse distances of a sample, StatStack), DRAM bytes");
    return e;
}

json Estimator::memory_json(double cycles) const {
    json out = json::object();
    if (m_c.ideal_memory) {
        json ideal = json::object();
        double reads = 0, writes = 0, rb = 0, wb = 0;
        for (int k = 0; k < kDataKindCount; ++k) {
            const KindCounts& kc = m_kinds[size_t(k)];
            if (kc.reads + kc.writes <= 0) continue;
            ideal["by_kind"][data_kind_name(DataKind(k))] = counters_json(kc.reads, kc.writes, kc.reads, kc.read_bytes, kc.write_bytes);
            reads += kc.reads, writes += kc.writes, rb += kc.read_bytes, wb += kc.write_bytes;
        }
        StatsWriter(ideal_memory_stats(), out["ideal_memory"])
            .merge(counters_json(reads, writes, reads, rb, wb))
            .set("by_kind", ideal.value("by_kind", json::object()))
            .done();
        return out;
    }
    const double units = m_c.traversal.units, line = m_c.l1.line_bytes;
    json l1 = json::object(), l2 = json::object(), dram = json::object();
    double t1[5] = {}, t2[5] = {}, td[4] = {};  // reads, writes, hits, read bytes, write bytes
    for (int k = 0; k < kDataKindCount; ++k) {
        const KindCounts& kc = m_kinds[size_t(k)];
        if (kc.reads + kc.writes <= 0) continue;
        const char* name = data_kind_name(DataKind(k));
        const double v1[5] = {kc.reads, kc.writes, kc.reads - kc.l1_misses, kc.read_bytes, kc.write_bytes};
        const double v2[5] = {kc.l1_misses, kc.writes, kc.l1_misses - kc.l2_misses, kc.l1_misses * line, kc.write_bytes};
        const double vd[4] = {kc.l2_misses, kc.writes, kc.l2_misses * line, kc.write_bytes};
        l1["by_kind"][name] = counters_json(v1[0] / units, v1[1] / units, v1[2] / units, v1[3] / units, v1[4] / units);
        l2["by_kind"][name] = counters_json(v2[0], v2[1], v2[2], v2[3], v2[4]);
        dram["by_kind"][name] = {{"reads", vd[0]}, {"writes", vd[1]}, {"read_bytes", vd[2]}, {"write_bytes", vd[3]}};
        for (int i = 0; i < 5; ++i) t1[i] += v1[i], t2[i] += v2[i];
        for (int i = 0; i < 4; ++i) td[i] += vd[i];
    }
    auto cache_json = [&](const json& kinds, const double* t, double div, const CacheConfig& cc) {
        json j;
        StatsWriter(cache_stats(), j)
            .merge(counters_json(t[0] / div, t[1] / div, t[2] / div, t[3] / div, t[4] / div))
            .set("by_kind", kinds.value("by_kind", json::object()))
            .set("evictions", nullptr)  // not estimated
            .set("config", cache_config_json(cc, nullptr))
            .untimed()
            .done();
        return j;
    };
    json l1_one = cache_json(l1, t1, units, m_c.l1);
    for (uint32_t u = 0; u < m_c.traversal.units; ++u) out["l1"]["l1_" + std::to_string(u)] = l1_one;
    out["l2"] = cache_json(l2, t2, 1.0, m_c.l2);
    StatsWriter d(dram_stats(), out["dram"]);
    d.set("reads", td[0]).set("writes", td[1]).set("read_bytes", td[2]).set("write_bytes", td[3]);
    d.set("by_kind", dram.value("by_kind", json::object()));
    dram_bandwidth_stats(d, m_c.dram, td[2] + td[3], cycles, m_c.clock_ghz);
    d.set("bandwidth_over_time", json::array()).untimed().done();
    return out;
}

PredictedRates Estimator::rates() {
    count_kinds();
    PredictedRates r;
    double reads = 0, m1 = 0, m12 = 0;
    for (const KindCounts& kc : m_kinds) reads += kc.reads, m1 += kc.l1_misses, m12 += kc.l2_misses;
    r.l1_read_hit_rate = reads > 0 ? 1.0 - m1 / reads : 0.0;
    r.l2_read_hit_rate = m1 > 0 ? 1.0 - m12 / m1 : 0.0;
    r.dram_read_lines = m12;
    return r;
}

}  // namespace

AnalyticEstimate estimate_analytic(const SimConfig& config, const AnalyticProfile& profile) {
    MissModel misses(profile);
    return Estimator(config, profile, misses).run();
}

PredictedRates predicted_rates(const SimConfig& config, const AnalyticProfile& profile) {
    MissModel misses(profile);
    return Estimator(config, profile, misses).rates();
}

std::vector<PredictedRates> frame_hit_rates(const SimConfig& config, const AnalyticProfile& profile, size_t frames) {
    std::vector<PredictedRates> out;
    const std::vector<FrameSample>& samples = profile.frame_samples;
    if (samples.empty() || frames == 0) return out;
    MissModel misses(profile);
    const MissTables tables(config, misses);
    const PredictedRates run = Estimator(config, profile, misses).rates();
    // Each sample's miss ratios (L1 over reads, L2 over L1 misses), and their means.
    std::vector<std::pair<double, double>> miss;
    double mean1 = 0, mean2 = 0;
    for (const FrameSample& f : samples) {
        double reads = 0, m1 = 0, m12 = 0;
        for (const auto& [key, count] : f.reads.cells) {
            const auto [p1, p12] = tables.cell(key);
            reads += count, m1 += count * p1, m12 += count * p12;
        }
        miss.push_back({reads > 0 ? m1 / reads : 0.0, m1 > 0 ? m12 / m1 : 0.0});
        mean1 += miss.back().first / double(samples.size()), mean2 += miss.back().second / double(samples.size());
    }
    auto rates = [&](double r1, double r2) {
        PredictedRates r;
        const double l1 = mean1 > 0 ? (1.0 - run.l1_read_hit_rate) * r1 / mean1 : 1.0 - run.l1_read_hit_rate;
        const double l2 = mean2 > 0 ? (1.0 - run.l2_read_hit_rate) * r2 / mean2 : 1.0 - run.l2_read_hit_rate;
        r.l1_read_hit_rate = std::clamp(1.0 - l1, 0.0, 1.0);
        r.l2_read_hit_rate = std::clamp(1.0 - l2, 0.0, 1.0);
        return r;
    };
    for (size_t f = 0; f < frames; ++f) {
        size_t k = 0;
        while (k + 1 < samples.size() && samples[k + 1].frame <= f) ++k;
        if (f <= samples.front().frame || k + 1 == samples.size()) {
            const size_t near = f <= samples.front().frame ? 0 : k;
            out.push_back(rates(miss[near].first, miss[near].second));
            continue;
        }
        const double a = double(f - samples[k].frame) / double(samples[k + 1].frame - samples[k].frame);
        out.push_back(rates(miss[k].first + a * (miss[k + 1].first - miss[k].first),
                            miss[k].second + a * (miss[k + 1].second - miss[k].second)));
    }
    return out;
}

FormEstimator::FormEstimator(const AnalyticProfile& profile)
    : m_profile(profile), m_misses(std::make_unique<MissModel>(profile)) {}

FormEstimator::~FormEstimator() = default;

ClosedForm FormEstimator::operator()(const SimConfig& config) const {
    return Estimator(config, m_profile, *m_misses).form();
}

}  // namespace rtsim
