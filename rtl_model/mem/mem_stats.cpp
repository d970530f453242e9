#include "rtl_model/mem/mem_stats.h"

namespace rtsim {

namespace {
nlohmann::json counters_json(const MemCounters& c) {
    double hit_rate = c.reads ? double(c.read_hits + c.merged) / double(c.reads) : 0.0;
    return {{"reads", c.reads},           {"writes", c.writes},           {"read_hits", c.read_hits},
            {"merged", c.merged},         {"hit_rate", hit_rate},         {"read_bytes", c.read_bytes},
            {"write_bytes", c.write_bytes}};
}
}  // namespace

MemCounters MemStats::total() const {
    MemCounters t;
    for (const MemCounters& c : m_kinds) t += c;
    return t;
}

nlohmann::json MemStats::to_json() const {
    nlohmann::json j = counters_json(total());
    for (int k = 0; k < kDataKindCount; ++k)
        if (m_kinds[k].reads || m_kinds[k].writes) j["by_kind"][data_kind_name(DataKind(k))] = counters_json(m_kinds[k]);
    return j;
}

}  // namespace rtsim
