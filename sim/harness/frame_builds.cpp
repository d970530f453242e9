// Each frame's build jobs (frame_builds.h).
#include "sim/harness/frame_builds.h"

#include "traces/common/error.h"

#include <algorithm>
#include <string>

namespace rtsim {

using nlohmann::json;

namespace {

/// BLAS b's slices of the image's "blas_R" regions: written all, read where they hold triangles.
BuildJob blas_job(const AccelImage& image, const json& blas, const json& stats, const json& record) {
    BuildJob job;
    job.refit = record.value("action", std::string()) == "refit";
    job.triangles = record.value("triangles", uint64_t(0));
    job.tree_nodes = record["tree_nodes"].is_number() ? record["tree_nodes"].get<uint64_t>() : 0;
    // An oriented BLAS fits its rotations after each build and refit (obvh.h): the node boxes
    // its fit computed, or for a trace that did not record them, every node in every frame.
    const json fit = stats.contains("obvh2") ? stats["obvh2"].value("fit_node_frames", json(nullptr)) : json(nullptr);
    const json& params = blas.value("params", json::object());
    if (fit.is_number()) job.fit_node_frames = fit.get<uint64_t>();
    else if (params.contains("rotations") && blas.at("count").contains("nodes"))
        job.fit_node_frames = params["rotations"].size() * blas.at("count").at("nodes").get<uint64_t>();
    for (const auto& [name, first] : blas.at("first").items()) {
        const Region* r = nullptr;
        for (const Region& reg : image.regions)
            if (reg.name == "blas_" + name) r = &reg;
        if (!r) continue;
        const uint64_t count = blas.at("count").at(name).get<uint64_t>();
        const BuildJob::Range range{r->address(first.get<uint64_t>()), count * r->record_bytes};
        job.writes.push_back(range);
        if (r->kind == DataKind::triangle) job.reads.push_back(range);
    }
    return job;
}

/// The frame's TLAS: its nodes and instance records written, the records read (the instances'
/// boxes and transforms its build starts from).
BuildJob tlas_job(const AccelImage& image, const json& slice) {
    BuildJob job;
    const json& rec = slice["build"]["tlas"];
    job.refit = rec.value("action", std::string()) == "refit";
    job.triangles = slice.at("instances_count").get<uint64_t>();
    job.tree_nodes = rec["tree_nodes"].is_number() ? rec["tree_nodes"].get<uint64_t>() : 0;
    const Region& nodes = image.region("tlas_nodes");
    const Region& records = image.region("instances");
    const BuildJob::Range node_range{nodes.address(slice.at("tlas_first").get<uint64_t>()),
                                     slice.at("tlas_count").get<uint64_t>() * nodes.record_bytes};
    const BuildJob::Range record_range{records.address(slice.at("instances_first").get<uint64_t>()),
                                       job.triangles * records.record_bytes};
    job.writes = {node_range, record_range};
    job.reads = {record_range};
    return job;
}

}  // namespace

std::vector<std::vector<BuildJob>> frame_build_jobs(const Accel& accel) {
    const AccelImage& image = accel.image();
    std::vector<std::vector<BuildJob>> out;
    if (image.kind != "two_level" || !image.params.contains("frames")) return out;
    const json& frames = image.params.at("frames");
    const json& blases = image.params.at("blas");
    static const json kNoBlases = json::array(), kNoStats = json::object();
    const json& blas_stats =
        image.stats.contains("blas") && image.stats["blas"].is_array() ? image.stats["blas"] : kNoBlases;
    out.resize(frames.size());
    for (size_t f = 1; f < frames.size(); ++f) {
        const json& slice = frames[f];
        if (!slice.contains("build")) return {};  // a trace from before frames recorded builds
        for (const json& record : slice["build"].value("blas", json::array())) {
            const size_t b = record.at("blas").get<size_t>();
            const json& stats = b < blas_stats.size() ? blas_stats[b] : kNoStats;
            out[f].push_back(blas_job(image, blases.at(b), stats, record));
        }
        out[f].push_back(tlas_job(image, slice));
    }
    return out;
}

void move_to_second_buffer(std::vector<std::vector<BuildJob>>& jobs) {
    // The memory map's regions take a 4 GiB granule or more each from 4 GiB up (memory_map.h):
    // 2^44 up stands clear of a map of fewer than 4,096 granules, and gives the second buffer
    // rows of its own in every bank.
    constexpr uint64_t kSecondBuffer = uint64_t(1) << 44;
    for (auto& frame : jobs)
        for (BuildJob& job : frame) {
            for (auto* ranges : {&job.reads, &job.writes})
                for (BuildJob::Range& r : *ranges) {
                    require(r.addr + r.bytes <= kSecondBuffer, "build_unit.overlap: a structure at or past 16 TiB has no "
                                                               "room for its second buffer");
                    r.addr += kSecondBuffer;
                }
        }
}

FrameBuildSchedule::FrameBuildSchedule(bool overlap, uint32_t frames, StartFn start, FinishFn finish)
    : m_overlap(overlap), m_frames(frames), m_start(std::move(start)), m_finish(std::move(finish)) {
    if (m_overlap && m_frames > 1) m_start(1, 0);
}

Cycle FrameBuildSchedule::ready(uint32_t f, Cycle end) {
    if (f >= m_frames) return end;
    if (!m_overlap) {
        m_start(f, end);
        return std::max(end, m_finish(f));
    }
    const Cycle begin = std::max(end, m_finish(f));  // its build ran beside the frame before
    if (f + 1 < m_frames) m_start(f + 1, begin);
    return begin;
}

}  // namespace rtsim
