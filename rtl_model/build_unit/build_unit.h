#pragma once
// The build unit (docs/model.md, "Build unit"): at each frame barrier of a moving scene it
// builds or refits the frame's structures before the frame's rays may start, as a hardware
// BVH builder beside the traversal units would (Doyle et al. 2013; Viitanen et al. 2017), so
// a frame's time holds its build. Its reads and writes go through the shared L2 to DRAM: the
// frame's triangles read (once for a refit, rebuild_read_passes times for a rebuild), its new
// nodes and triangle records written at the addresses the frame's structures occupy, which
// leaves them in the L2 for the traversal that follows. Compute is a throughput (triangles or
// nodes per cycle); memory a window of outstanding line requests; the build ends when both
// have. Not modelled: overlapping a frame's build with the previous frame's traversal (async
// compute), and the skinning that produces the vertices (a shader's work).
#include <cstdint>
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
    /// {"frames", "busy_cycles", "compute_cycles", "stream_cycles", "rebuilt_triangles", "refit_nodes",
    ///  "fit_node_frames", "read_bytes", "written_bytes", "rebuilds", "refits"} (docs/stats.md, "build_unit").
    nlohmann::json stats_json() const;

private:
    /// Streams the ranges' lines through `m_mem` from `start`, paced at `cycles_per_line`
    /// and at most outstanding_lines in flight; returns the last completion.
    Cycle stream(const std::vector<BuildJob::Range>& ranges, bool write, Cycle start, double cycles_per_line,
                 uint64_t* bytes);

    const BuildUnitConfig& m_config;
    MemIf& m_mem;
    uint32_t m_line;
    FrameBuild m_total;
    uint64_t m_frames = 0, m_busy = 0, m_compute = 0, m_stream = 0;
};

/// model.build_unit in stats.json, declared once.
const StatBlock& build_unit_stats();

}  // namespace rtsim
