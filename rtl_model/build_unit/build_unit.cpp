// The build unit (build_unit.h).
#include "rtl_model/build_unit/build_unit.h"

#include <algorithm>
#include <cmath>
#include <deque>

namespace rtsim {

BuildUnit::BuildUnit(const BuildUnitConfig& config, MemIf& mem, uint32_t line_bytes)
    : m_config(config), m_mem(mem), m_line(std::max(1u, line_bytes)) {}

Cycle BuildUnit::stream(const std::vector<BuildJob::Range>& ranges, bool write, Cycle start, double cycles_per_line,
                        uint64_t* bytes) {
    std::deque<Cycle> in_flight;  // completions of the requests in flight, in issue order
    Cycle last = start, previous = start;  // one issuer: issue times never decrease
    uint64_t issued = 0;
    for (const BuildJob::Range& r : ranges) {
        const uint64_t first = r.addr / m_line, end = (r.addr + r.bytes + m_line - 1) / m_line;
        for (uint64_t line = first; line < end; ++line, ++issued) {
            // Paced by compute, and by the window: the oldest request must be back first.
            Cycle t = start + Cycle(std::floor(double(issued) * cycles_per_line));
            if (in_flight.size() >= m_config.outstanding_lines) {
                t = std::max(t, in_flight.front());
                in_flight.pop_front();
            }
            t = std::max(t, previous);
            previous = t;
            MemRequest req;
            req.addr = line * m_line;
            req.bytes = m_line;
            req.write = write;
            req.kind = write ? DataKind::node : DataKind::triangle;
            req.time = t;
            const Cycle done = m_mem.access(req);
            in_flight.push_back(done);
            last = std::max(last, done);
            *bytes += m_line;
        }
    }
    return last;
}

FrameBuild BuildUnit::run(const std::vector<BuildJob>& jobs, Cycle start) {
    FrameBuild out;
    out.start = out.end = start;
    Cycle t = start;
    for (const BuildJob& job : jobs) {
        // Compute: triangles (rebuild) or nodes (refit) at the unit's throughput; the job's lines
        // are spread over that time, reads before writes (a refit writes a node once its
        // children are read; a rebuild emits its nodes after its passes).
        // An oriented structure's fit follows either: a node's box in each table frame.
        const uint64_t fit_frames = job.fit_node_frames;
        const double compute = (job.refit ? double(job.tree_nodes) / m_config.refit_nodes_per_cycle
                                          : double(job.triangles) / m_config.rebuild_triangles_per_cycle) +
                               double(fit_frames) / m_config.fit_frames_per_cycle;
        uint64_t read_lines = 0, write_lines = 0;
        for (const auto& r : job.reads) read_lines += (r.bytes + m_line - 1) / m_line;
        for (const auto& r : job.writes) write_lines += (r.bytes + m_line - 1) / m_line;
        const uint32_t passes = job.refit ? 1 : m_config.rebuild_read_passes;
        const double lines = double(read_lines * passes + write_lines);
        const double pace = lines > 0 ? compute / lines : 0.0;
        Cycle read_end = t;
        for (uint32_t p = 0; p < passes; ++p)
            read_end = std::max(read_end, stream(job.reads, false, read_end, pace, &out.read_bytes));
        const Cycle write_end = stream(job.writes, true, read_end, pace, &out.written_bytes);
        m_compute += Cycle(std::ceil(compute));
        m_stream += write_end - t;
        t = std::max({write_end, t + Cycle(std::ceil(compute))});
        out.fit_node_frames += fit_frames;
        if (job.refit) {
            ++out.refits;
            out.refit_nodes += job.tree_nodes;
        } else {
            ++out.rebuilds;
            out.rebuilt_triangles += job.triangles;
        }
    }
    out.end = t;
    ++m_frames;
    m_busy += out.end - out.start;
    m_total.read_bytes += out.read_bytes;
    m_total.written_bytes += out.written_bytes;
    m_total.rebuilt_triangles += out.rebuilt_triangles;
    m_total.refit_nodes += out.refit_nodes;
    m_total.fit_node_frames += out.fit_node_frames;
    m_total.rebuilds += out.rebuilds;
    m_total.refits += out.refits;
    return out;
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
            {"busy_cycles", "cycles", "cycles the unit worked, summed over frames (each frame's rays waited for it)", true},
            {"compute_cycles", "cycles", "cycles its datapath needed at its throughput (triangles or nodes per cycle), summed over its jobs"},
            {"stream_cycles", "cycles", "cycles its memory stream took (reads, then writes, through the L2), summed over its jobs: a job takes the longer of the two"},
            {"rebuilt_triangles", "triangles", "triangles of the structures it rebuilt"},
            {"refit_nodes", "nodes", "binary-tree nodes of the structures it refitted"},
            {"fit_node_frames", "node frames", "oriented BVHs (obvh2): the node boxes the fits of the structures it built or refitted computed, one per node and frame (every table frame; with kept rotations only the frames of each node's oriented ancestors), at `fit_frames_per_cycle`; 0 without them"},
            {"read_bytes", "bytes", "bytes it read through the L2 (triangles; a rebuild's passes each)"},
            {"written_bytes", "bytes", "bytes it wrote through the L2 (the frames' nodes, triangle records, instances)"},
            {"rebuilds", "structures", "structures (BLASes and TLASes) it rebuilt"},
            {"refits", "structures", "structures it refitted"},
            {"share", "fraction", "busy_cycles over the run's cycles: the part of the run the traversal waited for builds (the verdict's `build` side)"},
        }};
    return block;
}

RTSIM_REGISTER_STAT_BLOCK(build_unit_stats)

}  // namespace rtsim
