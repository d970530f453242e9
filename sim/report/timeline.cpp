#include "sim/report/timeline.h"

#include <fstream>

#include <nlohmann/json.hpp>

#include "traces/common/error.h"

namespace rtsim {

void Timeline::ray(const RayResult& r, uint8_t kind) {
    if (m_spans.size() < kMaxRays) m_spans.push_back({r.start, r.end, r.id, r.unit, r.context, kind});
}

void Timeline::write(const std::string& path, uint32_t units, const std::vector<uint64_t>& dram_bytes,
                     uint64_t bucket_cycles) const {
    using nlohmann::json;
    const double us_per_cycle = 1.0 / (m_clock_ghz * 1000.0);
    json events = json::array();
    for (uint32_t u = 0; u < units; ++u)
        events.push_back({{"name", "process_name"}, {"ph", "M"}, {"pid", u}, {"args", {{"name", "traversal unit " + std::to_string(u)}}}});
    events.push_back({{"name", "process_name"}, {"ph", "M"}, {"pid", units}, {"args", {{"name", "DRAM"}}}});
    for (const Span& s : m_spans)
        events.push_back({{"name", ray_kind_name(RayKind(s.kind))},
                          {"cat", "ray"},
                          {"ph", "X"},
                          {"ts", double(s.start) * us_per_cycle},
                          {"dur", double(s.end - s.start) * us_per_cycle},
                          {"pid", s.unit},
                          {"tid", s.context},
                          {"args", {{"ray", s.id}, {"cycles", s.end - s.start}}}});
    for (size_t b = 0; b < dram_bytes.size(); ++b)
        events.push_back({{"name", "DRAM bandwidth"},
                          {"ph", "C"},
                          {"ts", double(b * bucket_cycles) * us_per_cycle},
                          {"pid", units},
                          {"args", {{"GB/s", double(dram_bytes[b]) / double(bucket_cycles) * m_clock_ghz}}}});
    std::ofstream out(path);
    require(bool(out), path + ": cannot write the timeline");
    out << json{{"traceEvents", events}, {"displayTimeUnit", "ns"}}.dump() << "\n";
}

}  // namespace rtsim
