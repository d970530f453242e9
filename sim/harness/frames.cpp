// Animated traces in the harness (frames.h).
#include "sim/harness/frames.h"

#include <algorithm>

#include "traces/common/error.h"

namespace rtsim {

using nlohmann::json;

FrameRayStream::FrameRayStream(TraceReader& reader, std::vector<FrameRecord> frames)
    : m_reader(reader), m_frames(std::move(frames)), m_total(reader.section(SectionKind::rays).record_count) {
    begin_frame(0);
}

void FrameRayStream::begin_frame(uint32_t f) {
    m_next = m_frames.at(f).first_ray;
    m_end = m_next + m_frames[f].rays;
}

size_t FrameRayStream::read_chunk(size_t max, std::vector<RayJob>* out) {
    const size_t n = size_t(std::min<uint64_t>(max, m_end - m_next));
    if (n == 0) return 0;
    read_ray_jobs(m_reader, m_next, n, &m_buffer, out);
    m_next += n;
    return n;
}

FrameRecorder::FrameRecorder(const SimConfig& config, std::vector<FrameRecord> frames, json manifest_frames)
    : m_config(config), m_frames(std::move(frames)), m_manifest_frames(std::move(manifest_frames)) {}

namespace {

json hit_rate(const MemCounters& now, const MemCounters& before) {
    const double reads = double(now.reads - before.reads);
    const double served = double(now.read_hits + now.merged - before.read_hits - before.merged);
    return reads > 0 ? json(served / reads) : json(nullptr);
}

}  // namespace

void FrameRecorder::untimed() {
    for (uint32_t f = 0; f < m_frames.size(); ++f) {
        frame_end(f, 0, MemoryTotals{});
        for (const char* key : {"start_cycle", "end_cycle", "cycles", "mrays_per_second", "dram_bytes",
                                "dram_bytes_per_ray", "l1_hit_rate", "l2_hit_rate", "build_cycles", "build_wait_cycles", "build_share",
                                "build_read_bytes", "build_written_bytes"})
            m_out.back()[key] = nullptr;
    }
}

void FrameRecorder::frame_end(uint32_t f, Cycle cycle, const MemoryTotals& totals) {
    const uint64_t rays = m_frames.at(f).rays;
    const Cycle cycles = cycle - std::min(cycle, m_last_cycle);
    const double seconds = double(cycles) / (m_config.clock_ghz * 1e9);
    const double dram = double(totals.dram.read_bytes + totals.dram.write_bytes - m_last.dram.read_bytes -
                               m_last.dram.write_bytes);
    json tlas_ms = nullptr, tlas_nodes = nullptr, sah_ratio = nullptr;
    uint64_t blas_rebuilt = 0, blas_refit = 0;
    if (m_manifest_frames.is_object() && m_manifest_frames.contains("per_frame") &&
        f < m_manifest_frames["per_frame"].size()) {
        const json& mf = m_manifest_frames["per_frame"][f];
        tlas_ms = mf.value("tlas_build_ms", json(nullptr));
        tlas_nodes = mf.value("tlas_nodes", json(nullptr));
        // The deforming BLASes' policy decisions (traces/accel/two_level/frame_policy.h).
        if (mf.contains("build") && mf["build"].contains("blas"))
            for (const json& b : mf["build"]["blas"]) {
                (b.value("action", std::string()) == "refit" ? blas_refit : blas_rebuilt) += 1;
                if (b["sah_ratio"].is_number())
                    sah_ratio = sah_ratio.is_null() ? b["sah_ratio"].get<double>()
                                                    : std::max(sah_ratio.get<double>(), b["sah_ratio"].get<double>());
            }
    }
    const FrameBuild build = f < m_builds.size() ? m_builds[f] : FrameBuild{};
    const Cycle build_cycles = build.end - build.start;
    // What the frame's rays waited for its build after the frame before it ended: all of it at
    // the barrier, what was left of it beside the previous frame's rays (build_unit.overlap).
    const Cycle build_wait = build_cycles && build.end > m_last_cycle ? build.end - m_last_cycle : 0;
    const bool memory = !m_config.ideal_memory;
    m_out.push_back({{"frame", f},
                     {"rays", rays},
                     {"first_ray", m_frames[f].first_ray},
                     {"start_cycle", m_last_cycle},
                     {"end_cycle", cycle},
                     {"cycles", cycles},
                     {"mrays_per_second", seconds > 0 ? double(rays) / seconds / 1e6 : 0.0},
                     {"dram_bytes", dram},
                     {"dram_bytes_per_ray", rays ? dram / double(rays) : 0.0},
                     {"l1_hit_rate", memory ? hit_rate(totals.l1, m_last.l1) : json(nullptr)},
                     {"l2_hit_rate", memory ? hit_rate(totals.l2, m_last.l2) : json(nullptr)},
                     {"tlas_nodes", tlas_nodes},
                     {"tlas_build_ms", tlas_ms},
                     {"blas_rebuilt", blas_rebuilt},
                     {"blas_refit", blas_refit},
                     {"blas_sah_ratio", sah_ratio},
                     {"build_cycles", build_cycles},
                     {"build_wait_cycles", build_wait},
                     {"build_share", cycles ? double(build_cycles) / double(cycles) : 0.0},
                     {"build_read_bytes", build.read_bytes},
                     {"build_written_bytes", build.written_bytes}});
    m_last = totals;
    m_last_cycle = cycle;
}

uint64_t FrameRecorder::build_wait_cycles() const {
    uint64_t sum = 0;
    for (const json& f : m_out)
        if (f["build_wait_cycles"].is_number()) sum += f["build_wait_cycles"].get<uint64_t>();
    return sum;
}

const StatBlock& frame_stats() {
    static const StatBlock block{
        "frames[]",
        {
            {"frame", "", "frame index"},
            {"rays", "rays", "the frame's rays"},
            {"sampled_rays", "rays", "sampled runs only: the frame's rays the sample simulated (its clusters'); then `cycles`, `start_cycle`, `end_cycle` and `mrays_per_second` are the estimate for all its rays and `dram_bytes` is scaled from its sampled rays' (the whole sample's for a frame without a cluster)", true, true},
            {"first_ray", "ray", "the frame's first ray's index in the trace"},
            {"start_cycle", "cycles", "the previous frame's last finish (0 for frame 0)", true},
            {"end_cycle", "cycles", "this frame's last finish", true},
            {"cycles", "cycles", "`end_cycle - start_cycle`: the frame's time, its cold start and tail included", true},
            {"mrays_per_second", "Mrays/s", "`rays / (cycles / clock_ghz)`, in millions", true},
            {"dram_bytes", "bytes", "DRAM reads + writes during the frame", true},
            {"dram_bytes_per_ray", "bytes/ray", "`dram_bytes / rays`", true},
            {"l1_hit_rate", "fraction", "(read_hits + merged) / reads during the frame; `null` with `ideal_memory`", true},
            {"l2_hit_rate", "fraction", "the L2's the same way", true},
            {"tlas_nodes", "nodes", "the frame's TLAS nodes (from the trace's manifest; `null` without frames)"},
            {"tlas_build_ms", "ms", "host wall time the tracer took to build the frame's TLAS and instance records (manifest; `null` without frames): not simulated"},
            {"blas_rebuilt", "structures", "deforming meshes' BLASes the frame built afresh (trace manifest; --frame-policy)"},
            {"blas_refit", "structures", "deforming meshes' BLASes the frame refitted"},
            {"blas_sah_ratio", "ratio", "largest SAH cost of the frame's deforming BLASes over their cost at their last rebuild; `null` without deforming geometry"},
            {"build_cycles", "cycles", "the build unit's time on the frame's structures (built or refitted: before its rays, or with `build_unit.overlap` beside the previous frame's; 0 for frame 0, whose exist before the run)", true},
            {"build_wait_cycles", "cycles", "what the frame's rays waited for its structures after the previous frame ended: `build_cycles` at the barrier, what was left of the build with `build_unit.overlap`", true},
            {"build_share", "fraction", "`build_cycles / cycles`", true},
            {"build_read_bytes", "bytes", "bytes the build unit read for the frame", true},
            {"build_written_bytes", "bytes", "bytes the build unit wrote for the frame", true},
        }};
    return block;
}

RTSIM_REGISTER_STAT_BLOCK(frame_stats)

}  // namespace rtsim
