// Record checks shared by every trace reader (trace_checks.h).
#include "traces/format/trace_checks.h"

#include <string>

#include "traces/common/error.h"

namespace rtsim {

void check_ray_sections(const TraceReader& reader) {
    const uint64_t rays = reader.section(SectionKind::rays).record_count;
    const uint64_t hits = reader.section(SectionKind::hits).record_count;
    const uint64_t work = reader.section(SectionKind::work).record_count;
    require(hits == rays && work == rays,
            reader.path() + ": sections RAYS, HITS and WORK have different record counts (" + std::to_string(rays) +
                ", " + std::to_string(hits) + ", " + std::to_string(work) + "); each holds one record per ray");
}

std::vector<FrameRecord> read_frame_table(TraceReader& reader, uint32_t accel_frames) {
    const std::string& path = reader.path();
    const uint64_t rays = reader.section(SectionKind::rays).record_count;
    std::vector<FrameRecord> frames;
    if (reader.has(SectionKind::frames)) frames = reader.read_all<FrameRecord>(SectionKind::frames);
    else frames.push_back(FrameRecord{0, rays});
    require(frames.size() == accel_frames,
            path + ": the trace has " + std::to_string(frames.size()) + " frame(s) (section FRMS) but its structure " +
                std::to_string(accel_frames));
    uint64_t next = 0;
    for (size_t f = 0; f < frames.size(); ++f) {
        require(frames[f].first_ray == next && frames[f].rays <= rays - next,
                path + ": section FRMS: frame " + std::to_string(f) + " (rays [" + std::to_string(frames[f].first_ray) +
                    ", +" + std::to_string(frames[f].rays) + ")) does not follow frame " + std::to_string(f) +
                    " - 1 within the trace's " + std::to_string(rays) + " rays");
        next += frames[f].rays;
    }
    require(next == rays, path + ": section FRMS: the frames hold " + std::to_string(next) + " of the trace's " +
                              std::to_string(rays) + " rays");
    return frames;
}

}  // namespace rtsim
