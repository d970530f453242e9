#pragma once
// Configuration of the build unit (build_unit.h): the hardware that builds or refits a moving
// scene's structures at each frame barrier (docs/model.md, "Build unit").
#include <cstdint>

namespace rtsim {

struct BuildUnitConfig {
    /// Price each frame's build on the unit (animated traces whose frames record their builds).
    bool enabled = true;
    /// Rebuild throughput. A round figure, not a measured one: hardware LBVH/HLBVH builders
    /// stream about a primitive a cycle through their Morton and emit stages (MergeTree,
    /// Viitanen et al. 2017, is 5x faster than the binned-SAH unit of Doyle et al. 2013, which
    /// rebuild_triangles_per_cycle = 0.2 models).
    double rebuild_triangles_per_cycle = 1.0;
    /// Refit throughput: a node's box is the union of its children's (six min/max) per cycle.
    double refit_nodes_per_cycle = 1.0;
    /// Oriented BVHs (obvh2): a fit's throughput, a node's box in one table frame per cycle (the
    /// refit datapath behind a rotator of its children's boxes' points: an assumption; published
    /// OBB builders fit on GPU shaders, Vitsas et al. 2023).
    double fit_frames_per_cycle = 1.0;
    /// Passes a rebuild reads its triangles in (Morton codes, the sort's external passes, the
    /// emit): MergeTree's traffic is a third of the binned-SAH builder's; 3 passes for the LBVH-style
    /// unit, about 9 for a binned SAH unit.
    uint32_t rebuild_read_passes = 3;
    /// Line requests the unit keeps in flight to the L2 (its stream buffer).
    uint32_t outstanding_lines = 32;
    /// On-chip working memory (Morton keys, the sort's runs, the emitted nodes' staging): area only.
    uint32_t sram_kib = 64;
    /// Build the next frame's structures while the current frame's rays run (async compute into
    /// a second buffer, as engines overlap BVH builds with the previous frame's rendering) instead
    /// of at the barrier between them (sim/harness/frame_builds.h, FrameBuildSchedule).
    bool overlap = false;

    template <class V>
    void visit(V& v) {
        v.flag("enabled", enabled, "Price each frame's build or refit on the build unit at the frame barrier (animated traces)");
        v.field("rebuild_triangles_per_cycle", rebuild_triangles_per_cycle, "triangles/cycle", "Rebuild throughput (LBVH-style unit about 1; a binned-SAH unit about 0.2)", 0.001, 64);
        v.field("refit_nodes_per_cycle", refit_nodes_per_cycle, "nodes/cycle", "Refit throughput: binary-tree nodes whose box is recomputed per cycle", 0.001, 64);
        v.field("fit_frames_per_cycle", fit_frames_per_cycle, "node frames/cycle", "Oriented BVHs: a fit's throughput, node boxes computed in one frame per cycle (each build's and refit's fit_node_frames)", 0.001, 1024);
        v.field("rebuild_read_passes", rebuild_read_passes, "passes", "Times a rebuild reads its triangles (keys, sort passes, emit)", 1, 64);
        v.field("outstanding_lines", outstanding_lines, "lines", "Line requests the unit keeps in flight to the L2", 1, 4096);
        v.field("sram_kib", sram_kib, "KiB", "The unit's working SRAM (area only)", 1, 1u << 16);
        v.flag("overlap", overlap, "Build the next frame's structures into a second buffer while the current frame's rays run (async compute), instead of at the barrier between them");
    }
};

}  // namespace rtsim
