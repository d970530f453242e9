#include "sim/harness/model_errors.h"

#include <vector>

#include "sim/harness/trace_stream.h"
#include "traces/common/error.h"

namespace rtsim {

std::string unwrap_report(const std::string& report) {
    std::string text = report;
    const std::string prefix = "uncaught exception: ";
    const size_t at = text.find(prefix);
    if (at != std::string::npos) text = text.substr(at + prefix.size());
    // Drop SystemC's location lines; keep the message itself.
    for (const char* marker : {"\nIn file:", "\nIn process:"}) {
        const size_t cut = text.find(marker);
        if (cut != std::string::npos) text = text.substr(0, cut);
    }
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
    return text;
}

std::string first_failing_ray(const Accel& accel, TraceReader& reader) {
    const uint64_t total = reader.section(SectionKind::rays).record_count;
    std::vector<RayRecord> buffer;
    std::vector<RayJob> jobs;
    for (uint64_t first = 0; first < total; first += jobs.size()) {
        jobs.clear();
        read_ray_jobs(reader, first, size_t(std::min<uint64_t>(65536, total - first)), &buffer, &jobs);
        if (jobs.empty()) break;
        for (const RayJob& job : jobs) {
            try {
                accel.trace(job.ray, job.any_hit ? TraversalMode::any_hit : TraversalMode::closest_hit);
            } catch (const Error& e) {
                return "ray " + std::to_string(job.id) + ": " + e.what();
            }
        }
    }
    return "";
}

}  // namespace rtsim
