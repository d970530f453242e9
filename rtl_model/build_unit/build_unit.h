#pragma once
// The build unit (docs/model.md, "Build unit"): at each frame barrier of a moving scene it
// builds or refits the frame's structures before the frame's rays may start, as a hardware
// BVH builder beside the traversal units would (Doyle et al. 2013; Viitanen et al. 2017), so
// a frame's time holds its build. Its reads and writes go through the shared L2 to DRAM: the
// frame's triangles read (once for a refit, rebuild_read_passes times for a rebuild), its new
// nodes and triangle records written at the addresses the frame's structures occupy, which
// leaves them in the L2 for the traversal that follows. Compute is a throughput (triangles or
// nodes per cycle); memory a window of outstanding line requests; the build ends when both
// have. With build_unit.overlap a frame's build runs beside the previous frame's rays (async
// compute into a second buffer: build_streamer.h issues its requests in time, the harness's
// FrameBuildSchedule orders the frames). Not modelled: the skinning that produces the vertices
// (a shader's work).
#include <cstdint>
#include <deque>
#include <vector>

#include <nlohmann/json.hpp>

#include "rtl_model/build_unit/build_unit_config.h"
#include "rtl_model/common/interfaces.h"
#include "rtl_model/common/stats.h"

namespace rtsim {

/// One structure a frame builds or refits: its work and the byte ranges it reads and writes.
struct BuildJob {
    bool refit = false;
    uint64_t triangles = 0;   ///< triangles it reads (a rebuild's primitives)
    uint64_t tree_nodes = 0;  ///< binary-tree nodes a refit recomputes
    /// An oriented BVH (obvh2): the node boxes its fit computes, one per node and frame (every
    /// rotation of the table, or with kept rotations each oriented ancestor's; docs/accel.md,
    /// "obvh2"); 0 for an axis-aligned structure.
    uint64_t fit_node_frames = 0;
    struct Range {
        uint64_t addr = 0, bytes = 0;
    };
    std::vector<Range> reads, writes;
};

/// What a frame's build did.
struct FrameBuild {
    Cycle start = 0, end = 0;
    uint64_t read_bytes = 0, written_bytes = 0;
    uint64_t rebuilt_triangles = 0, refit_nodes = 0;
    uint64_t fit_node_frames = 0;  ///< oriented fits: the node boxes they computed (BuildJob's)
    uint32_t rebuilds = 0, refits = 0;
};

class BuildUnit {
public:
    /// `mem`: the shared memory level below the traversal units (the L2, or ideal memory).
    BuildUnit(const BuildUnitConfig& config, MemIf& mem, uint32_t line_bytes);
    /// Runs `jobs` from cycle `start`; returns what it did (end: the cycle the last finished).
    FrameBuild run(const std::vector<BuildJob>& jobs, Cycle start);
    /// The same in steps, for a build that runs beside the traversal (build_unit.overlap): begin
    /// issues nothing, issue_until issues the line requests due by a cycle (the build_streamer's
    /// process, in time with the units' requests), finish issues the rest and returns what it
    /// did. One build at a time; run() is begin() then finish().
    void begin(const std::vector<BuildJob>& jobs, Cycle start);
    bool active() const { return m_active; }
    /// A line request is left to issue (the build in progress until finish() either way).
    bool has_requests() { return m_active && settle(); }
    /// The issue cycle of the next line request (the build's end when none is left).
    Cycle next_issue();
    void issue_until(Cycle limit);
    FrameBuild finish();
    /// {"frames", "busy_cycles", "compute_cycles", "stream_cycles", "rebuilt_triangles", "refit_nodes",
    ///  "fit_node_frames", "read_bytes", "written_bytes", "rebuilds", "refits"} (docs/stats.md, "build_unit").
    nlohmann::json stats_json() const;

private:
    /// Moves to the next line request (ending streams and jobs that have none left); false when
    /// the build is done.
    bool settle();
    void start_job();
    void start_stream(Cycle start);
    void end_stream();
    /// The current stream's next request: its cycle (paced at the job's cycles per line, at
    /// most outstanding_lines in flight) and line.
    Cycle due() const;

    const BuildUnitConfig& m_config;
    MemIf& m_mem;
    uint32_t m_line;
    FrameBuild m_total;
    uint64_t m_frames = 0, m_busy = 0, m_compute = 0, m_stream = 0;
    // The build in progress: its jobs, the current job's streams (its read passes, then its
    // writes), the current stream's position and requests in flight.
    bool m_active = false;
    const std::vector<BuildJob>* m_jobs = nullptr;
    FrameBuild m_out;
    size_t m_job = 0;
    Cycle m_job_start = 0, m_read_end = 0;
    double m_job_compute = 0, m_pace = 0;
    uint32_t m_passes = 1, m_pass = 0;  ///< streams 0..passes-1 read, stream `passes` writes
    bool m_in_stream = false;
    size_t m_range = 0;
    uint64_t m_line_at = 0, m_issued = 0;
    Cycle m_stream_start = 0, m_previous = 0, m_stream_last = 0;
    std::deque<Cycle> m_in_flight;  ///< completions of the stream's requests in flight, in issue order
};

/// model.build_unit in stats.json, declared once.
const StatBlock& build_unit_stats();

}  // namespace rtsim
