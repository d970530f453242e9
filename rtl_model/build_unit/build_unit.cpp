// The build unit (build_unit.h).
#include "rtl_model/build_unit/build_unit.h"

#include <algorithm>
#include <cmath>
#include <deque>

#include "traces/common/error.h"

namespace rtsim {

BuildUnit::BuildUnit(const BuildUnitConfig& config, MemIf& mem, uint32_t line_bytes)
    : m_config(config), m_mem(mem), m_line(std::max(1u, line_bytes)) {}

FrameBuild BuildUnit::run(const std::vector<BuildJob>& jobs, Cycle start) {
    begin(jobs, start);
    return finish();
}

void BuildUnit::begin(const std::vector<BuildJob>& jobs, Cycle start) {
    require(!m_active, "build unit: a build began before the last one finished");
    m_active = true;
    m_jobs = &jobs;
    m_out = FrameBuild{};
    m_out.start = m_out.end = start;
    m_job = 0;
    m_job_start = start;
    m_in_stream = false;
    if (!m_jobs->empty()) start_job();
}

void BuildUnit::start_job() {
    // Compute: triangles (rebuild) or nodes (refit) at the unit's throughput; the job's lines
    // are spread over that time, reads before writes (a refit writes a node once its children
    // are read; a rebuild emits its nodes after its passes). An oriented structure's fit
    // follows either: a node's box in each table frame.
    const BuildJob& job = (*m_jobs)[m_job];
    m_job_compute = (job.refit ? double(job.tree_nodes) / m_config.refit_nodes_per_cycle
                               : double(job.triangles) / m_config.rebuild_triangles_per_cycle) +
                    double(job.fit_node_frames) / m_config.fit_frames_per_cycle;
    uint64_t read_lines = 0, write_lines = 0;
    for (const auto& r : job.reads) read_lines += (r.bytes + m_line - 1) / m_line;
    for (const auto& r : job.writes) write_lines += (r.bytes + m_line - 1) / m_line;
    m_passes = job.refit ? 1 : m_config.rebuild_read_passes;
    const double lines = double(read_lines * m_passes + write_lines);
    m_pace = lines > 0 ? m_job_compute / lines : 0.0;
    m_pass = 0;
    m_read_end = m_job_start;
    start_stream(m_read_end);
}

void BuildUnit::start_stream(Cycle start) {
    m_in_stream = true;
    m_range = 0;
    m_line_at = 0;
    m_issued = 0;
    m_stream_start = m_previous = m_stream_last = start;  // one issuer: issue times never decrease
    m_in_flight.clear();
}

void BuildUnit::end_stream() {
    m_in_stream = false;
    const BuildJob& job = (*m_jobs)[m_job];
    if (m_pass < m_passes) {  // a read pass: the next starts when this one's last line is back
        m_read_end = std::max(m_read_end, m_stream_last);
        ++m_pass;
        start_stream(m_read_end);
        return;
    }
    const Cycle write_end = m_stream_last;
    m_compute += Cycle(std::ceil(m_job_compute));
    m_stream += write_end - m_job_start;
    m_job_start = std::max({write_end, m_job_start + Cycle(std::ceil(m_job_compute))});
    m_out.fit_node_frames += job.fit_node_frames;
    if (job.refit) {
        ++m_out.refits;
        m_out.refit_nodes += job.tree_nodes;
    } else {
        ++m_out.rebuilds;
        m_out.rebuilt_triangles += job.triangles;
    }
    if (++m_job < m_jobs->size()) start_job();
}

bool BuildUnit::settle() {
    while (m_in_stream) {
        const BuildJob& job = (*m_jobs)[m_job];
        const auto& ranges = m_pass < m_passes ? job.reads : job.writes;
        for (; m_range < ranges.size(); ++m_range, m_line_at = 0) {
            const BuildJob::Range& r = ranges[m_range];
            const uint64_t first = r.addr / m_line, end = (r.addr + r.bytes + m_line - 1) / m_line;
            if (first + m_line_at < end) return true;
        }
        end_stream();
    }
    return false;
}

Cycle BuildUnit::due() const {
    // Paced by compute, and by the window: the oldest request must be back first.
    Cycle t = m_stream_start + Cycle(std::floor(double(m_issued) * m_pace));
    if (m_in_flight.size() >= m_config.outstanding_lines) t = std::max(t, m_in_flight.front());
    return std::max(t, m_previous);
}

Cycle BuildUnit::next_issue() { return m_active && settle() ? due() : m_job_start; }

void BuildUnit::issue_until(Cycle limit) {
    while (m_active && settle()) {
        const Cycle t = due();
        if (t > limit) return;
        if (m_in_flight.size() >= m_config.outstanding_lines) m_in_flight.pop_front();
        m_previous = t;
        const bool write = m_pass >= m_passes;
        const BuildJob::Range& r = (write ? (*m_jobs)[m_job].writes : (*m_jobs)[m_job].reads)[m_range];
        MemRequest req;
        req.addr = (r.addr / m_line + m_line_at) * m_line;
        req.bytes = m_line;
        req.write = write;
        req.kind = write ? DataKind::node : DataKind::triangle;
        req.time = t;
        const Cycle done = m_mem.access(req);
        m_in_flight.push_back(done);
        m_stream_last = std::max(m_stream_last, done);
        (write ? m_out.written_bytes : m_out.read_bytes) += m_line;
        ++m_line_at, ++m_issued;
    }
}

FrameBuild BuildUnit::finish() {
    issue_until(~Cycle(0));
    m_active = false;
    m_out.end = m_job_start;
    ++m_frames;
    m_busy += m_out.end - m_out.start;
    m_total.read_bytes += m_out.read_bytes;
    m_total.written_bytes += m_out.written_bytes;
    m_total.rebuilt_triangles += m_out.rebuilt_triangles;
    m_total.refit_nodes += m_out.refit_nodes;
    m_total.fit_node_frames += m_out.fit_node_frames;
    m_total.rebuilds += m_out.rebuilds;
    m_total.refits += m_out.refits;
    return m_out;
}

nlohmann::json BuildUnit::stats_json() const {
    return {{"frames", m_frames},
            {"busy_cycles", m_busy},
            {"compute_cycles", m_compute},
            {"stream_cycles", m_stream},
            {"rebuilt_triangles", m_total.rebuilt_triangles},
            {"refit_nodes", m_total.refit_nodes},
            {"fit_node_frames", m_total.fit_node_frames},
            {"read_bytes", m_total.read_bytes},
            {"written_bytes", m_total.written_bytes},
            {"rebuilds", m_total.rebuilds},
            {"refits", m_total.refits}};
}

}  // namespace rtsim

namespace rtsim {

const StatBlock& build_unit_stats() {
    static const StatBlock block{
        "model.build_unit",
        {
            {"frames", "frames", "frames whose structures the unit built or refitted (frame 0's exist before the run)"},
            {"busy_cycles", "cycles", "cycles the unit worked, summed over frames (at the barriers each frame's rays waited for it; with `overlap` beside the previous frame's rays)", true},
            {"compute_cycles", "cycles", "cycles its datapath needed at its throughput (triangles or nodes per cycle), summed over its jobs"},
            {"stream_cycles", "cycles", "cycles its memory stream took (reads, then writes, through the L2), summed over its jobs: a job takes the longer of the two"},
            {"rebuilt_triangles", "triangles", "triangles of the structures it rebuilt"},
            {"refit_nodes", "nodes", "binary-tree nodes of the structures it refitted"},
            {"fit_node_frames", "node frames", "oriented BVHs (obvh2): the node boxes the fits of the structures it built or refitted computed, one per node and frame (every table frame; with kept rotations only the frames of each node's oriented ancestors), at `fit_frames_per_cycle`; 0 without them"},
            {"read_bytes", "bytes", "bytes it read through the L2 (triangles; a rebuild's passes each)"},
            {"written_bytes", "bytes", "bytes it wrote through the L2 (the frames' nodes, triangle records, instances)"},
            {"rebuilds", "structures", "structures (BLASes and TLASes) it rebuilt"},
            {"refits", "structures", "structures it refitted"},
            {"share", "fraction", "the frames' `build_wait_cycles` over the run's cycles: the part of the run the traversal waited for builds (busy_cycles' share at the barriers, less with `overlap`; the verdict's `build` side)"},
        }};
    return block;
}

RTSIM_REGISTER_STAT_BLOCK(build_unit_stats)

}  // namespace rtsim
