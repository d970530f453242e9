#pragma once
// Animated traces in the harness (docs/model.md, "Frames"): the frame table (read and checked by
// traces/format/trace_checks.h), the ray stream cut at frame ends, and each frame's figures (cycles,
// Mrays/s, DRAM bytes per ray, cache hit rates) from the model's counters at the frame barrier.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <algorithm>

#include "rtl_model/build_unit/build_unit.h"
#include "rtl_model/common/stats.h"
#include "rtl_model/top/top.h"
#include "sim/config/config.h"
#include "sim/harness/trace_stream.h"
#include "traces/format/trace_checks.h"  // read_frame_table
#include "traces/format/trace_reader.h"

namespace rtsim {

/// Rays of the trace in order, each read ending at the current frame's last ray.
class FrameRayStream : public RayStream {
public:
    FrameRayStream(TraceReader& reader, std::vector<FrameRecord> frames);
    size_t read_chunk(size_t max, std::vector<RayJob>* out) override;
    uint64_t total_rays() const override { return m_total; }
    void begin_frame(uint32_t f) override;

private:
    TraceReader& m_reader;
    std::vector<FrameRecord> m_frames;
    uint64_t m_total = 0, m_next = 0, m_end = 0;
    std::vector<RayRecord> m_buffer;
};

/// Each frame's figures, from the memory counters at its barrier (stats.json "frames").
class FrameRecorder {
public:
    /// `manifest_frames`: the trace manifest's "frames" (TLAS build times), or null.
    FrameRecorder(const SimConfig& config, std::vector<FrameRecord> frames, nlohmann::json manifest_frames);
    /// Frame f's last ray finished at `cycle`; `totals` are the counters then.
    void frame_end(uint32_t f, Cycle cycle, const MemoryTotals& totals);
    /// The functional level: each frame's rays and TLAS build time, no timing.
    void untimed();
    /// Frame f's build on the build unit (rtl_model/build_unit/build_unit.h), before its rays.
    void set_build(uint32_t f, const FrameBuild& build) { m_builds.resize(std::max<size_t>(m_builds.size(), f + 1)); m_builds[f] = build; }
    /// The frames' build_wait_cycles summed: what the run's rays waited for builds (the build
    /// unit's busy cycles when it builds at the barriers; less beside the traversal).
    uint64_t build_wait_cycles() const;
    /// True once frame f's figures are recorded.
    bool recorded(uint32_t f) const { return f < m_out.size(); }
    /// [{frame, rays, start_cycle, cycles, mrays_per_second, dram_bytes_per_ray, l1_hit_rate,
    ///   l2_hit_rate, tlas_build_ms, ...}] (docs/stats.md, "Frames").
    const nlohmann::json& to_json() const { return m_out; }
    /// The figures, to rewrite (a sampled run's estimates: apply_sampling_to_frames).
    nlohmann::json& mutable_json() { return m_out; }

private:
    const SimConfig& m_config;
    std::vector<FrameRecord> m_frames;
    nlohmann::json m_manifest_frames;
    MemoryTotals m_last;
    Cycle m_last_cycle = 0;
    nlohmann::json m_out = nlohmann::json::array();
    std::vector<FrameBuild> m_builds;  ///< per frame (missing: no build priced)
};

/// One entry of stats.json "frames", declared once.
const StatBlock& frame_stats();

}  // namespace rtsim
