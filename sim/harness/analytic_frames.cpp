#include "sim/harness/analytic_frames.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <unordered_set>

#include "rtl_model/common/interfaces.h"
#include "rtl_model/top/top.h"
#include "sim/harness/frame_builds.h"
#include "sim/harness/frames.h"

namespace rtsim {

using nlohmann::json;

namespace {

/// The build unit's memory without a simulation: the L2 as a FIFO of its capacity in lines, and
/// one DRAM bus at the channels' peak rate. A read of a line in the L2 takes the L2's latency;
/// any other waits for the bus and then the unloaded L2-miss latency. A write is posted into the
/// L2 (its latency) and takes the bus once for its write-back. (A rebuild's second and third
/// passes over its triangles hit the L2 where they fit.)
class ClosedFormMemory : public MemIf {
public:
    explicit ClosedFormMemory(const SimConfig& c)
        : m_line_cycles(double(c.l2.line_bytes) / (double(c.dram.bytes_per_cycle) * c.dram.channels)),
          m_l2(c.l2.latency),
          m_miss(double(c.l2.latency) + c.dram.latency + std::ceil(double(c.l2.line_bytes) / c.dram.bytes_per_cycle)),
          m_line_bytes(c.l2.line_bytes),
          m_capacity(c.l2.lines()),
          m_ideal(c.ideal_memory) {}
    /// Beside the traversal (build_unit.overlap): a miss waits `factor` times its unloaded
    /// latency, as the traversal's own accesses do under its load.
    void load_with(double factor) { m_miss *= factor; }
    /// Bytes that took the DRAM bus so far (misses and write-backs).
    double bus_bytes() const { return m_bus_bytes; }
    Cycle access(const MemRequest& req) override {
        if (m_ideal) return req.time + 1;
        const uint64_t line = req.addr / m_line_bytes;
        const bool present = m_lines.count(line) != 0;
        if (!present) {
            m_lines.insert(line);
            m_order.push_back(line);
            if (m_order.size() > m_capacity) m_lines.erase(m_order.front()), m_order.pop_front();
        }
        if (!req.write && present) return req.time + Cycle(m_l2);
        const double start = std::max(double(req.time), m_bus);
        m_bus = start + m_line_cycles;
        m_bus_bytes += m_line_bytes;
        return Cycle(std::ceil(req.write ? double(req.time) + m_l2 : start + m_miss));
    }

private:
    double m_line_cycles, m_l2, m_miss;
    uint32_t m_line_bytes;
    uint64_t m_capacity;
    bool m_ideal;
    double m_bus = 0, m_bus_bytes = 0;
    std::unordered_set<uint64_t> m_lines;
    std::deque<uint64_t> m_order;
};

/// Counters of `reads` reads with `hits` hits (no rate known: none).
MemCounters counters(double reads, double hits, bool known) {
    MemCounters m;
    m.reads = uint64_t(std::llround(reads));
    if (known) m.read_hits = uint64_t(std::llround(hits));
    return m;
}

}  // namespace

std::vector<double> frame_step_work(TraceReader& reader, const std::vector<FrameRecord>& frames) {
    std::vector<double> out;
    std::vector<WorkRecord> buf(65536);
    for (const FrameRecord& f : frames) {
        double sum = 0;
        for (uint64_t first = f.first_ray; first < f.first_ray + f.rays; first += buf.size()) {
            const uint64_t count = std::min<uint64_t>(buf.size(), f.first_ray + f.rays - first);
            reader.read(SectionKind::work, first, count, buf.data());
            for (uint64_t i = 0; i < count; ++i) sum += plan_step_work(buf[i].counts());
        }
        out.push_back(sum);
    }
    return out;
}

AnalyticFrames estimate_frames(const SimConfig& config, const std::vector<FrameRecord>& frames,
                               const std::vector<double>& step_work, const json& manifest_frames,
                               const std::vector<std::vector<BuildJob>>& jobs, double traversal_cycles,
                               double mean_latency, const json& summary, const std::vector<PredictedRates>& rates) {
    AnalyticFrames out;
    FrameRecorder recorder(config, frames, manifest_frames);
    ClosedFormMemory memory(config);
    std::unique_ptr<BuildUnit> unit;
    if (config.build_unit.enabled && !jobs.empty()) unit = std::make_unique<BuildUnit>(config.build_unit, memory, config.l2.line_bytes);
    double work = 0;
    for (double w : step_work) work += w;
    const double per_work = work > 0 ? traversal_cycles / work : 0.0;
    const double dram_per_work = work > 0 ? summary.value("dram_bytes", 0.0) / work : 0.0;
    // A barrier empties the machine and the next frame fills it again: about one ray's latency
    // of lost overlap (the closed form's steady state has the first frame's fill in it already).
    const double refill = std::min(mean_latency, traversal_cycles);
    double t = 0, done_work = 0, build_bytes = 0;
    // Running read counters (any scale: only the rates are read back), each frame's reads at its
    // own hit rates where the analysis has them, else the run's. The L2's reads are the L1's
    // misses.
    const json run1 = summary.value("l1_hit_rate", json(nullptr)), run2 = summary.value("l2_hit_rate", json(nullptr));
    const bool known1 = run1.is_number(), known2 = run2.is_number();
    double l1_reads = 0, l1_hits = 0, l2_reads = 0, l2_hits = 0;
    // Beside a frame's rays the next frame's build shares the DRAM with them: the two take at
    // least their DRAM bytes at the channels' peak rate (a bound), and the build's misses wait as
    // long as the traversal's own do under its load.
    const double peak = double(config.dram.bytes_per_cycle) * config.dram.channels;
    const bool overlap = config.build_unit.overlap && unit;
    if (overlap) {
        // The traversal's loaded ray latency over its unloaded one (Little: contexts x cycles /
        // rays), which a build beside it sees on its misses too.
        double rays = 0;
        for (const FrameRecord& f : frames) rays += double(f.rays);
        const double contexts = double(config.traversal.units) * config.traversal.contexts();
        const double loaded = rays > 0 ? contexts * traversal_cycles / rays : 0.0;
        // (Clamped: a latency bound by the pipelines, not memory, would not slow the build's
        // misses that much; 4x is past any ratio the grids measured.)
        if (mean_latency > 0) memory.load_with(std::clamp(loaded / mean_latency, 1.0, 4.0));
    }
    // Builds at each barrier, or beside the previous frame's rays (build_unit.overlap).
    std::vector<Cycle> built(jobs.size(), 0);
    std::vector<double> built_bytes(jobs.size(), 0.0);
    FrameBuildSchedule schedule(
        overlap, uint32_t(jobs.size()),
        [&](uint32_t f, Cycle at) {
            built[f] = at;
            if (!unit || jobs[f].empty()) return;
            const double bus = memory.bus_bytes();
            const FrameBuild b = unit->run(jobs[f], at);
            recorder.set_build(f, b);
            build_bytes += double(b.read_bytes + b.written_bytes);
            built_bytes[f] = memory.bus_bytes() - bus;  // its DRAM share: misses and write-backs
            built[f] = b.end;
        },
        [&](uint32_t f) { return built[f]; });
    double shared_bound = 0;  // overlap: the next frame starts no earlier
    for (uint32_t f = 0; f < frames.size(); ++f) {
        if (f > 0) {
            // Kept fractional unless a build holds the frame (no drift of a cycle a frame).
            const double ended = std::max(t, shared_bound);
            const Cycle ready = schedule.ready(f, Cycle(std::ceil(ended)));
            t = double(ready) > std::ceil(ended) ? double(ready) : ended;
        }
        const double start = t;
        t += per_work * step_work[f] + (f > 0 ? refill : 0.0);
        if (overlap && f + 1 < built_bytes.size() && peak > 0)
            shared_bound = start + (dram_per_work * step_work[f] + built_bytes[f + 1]) / peak;
        done_work += step_work[f];
        // The frame's memory figures: the closed form's shared out by work.
        const bool own = rates.size() == frames.size();
        const double h1 = own ? rates[f].l1_read_hit_rate : known1 ? run1.get<double>() : 0.0;
        const double h2 = own ? rates[f].l2_read_hit_rate : known2 ? run2.get<double>() : 0.0;
        const double reads = step_work[f] * 1024;
        l1_reads += reads, l1_hits += reads * h1;
        l2_reads += reads * (1.0 - h1), l2_hits += reads * (1.0 - h1) * h2;
        MemoryTotals totals;
        totals.l1 = counters(l1_reads, l1_hits, known1);
        totals.l2 = counters(l2_reads, l2_hits, known2);
        totals.dram.read_bytes = uint64_t(std::llround(dram_per_work * done_work + build_bytes));
        recorder.frame_end(f, Cycle(std::ceil(t)), totals);
    }
    out.cycles = uint64_t(std::ceil(t));
    out.frames = recorder.to_json();
    if (unit) {
        out.build_unit = unit->stats_json();
        out.build_unit["share"] = out.cycles ? double(recorder.build_wait_cycles()) / double(out.cycles) : 0.0;
    }
    return out;
}

}  // namespace rtsim
