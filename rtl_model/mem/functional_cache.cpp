#include "rtl_model/mem/functional_cache.h"

namespace rtsim {

FunctionalCache::FunctionalCache(const CacheConfig& config) : m_config(config) {
    while ((1u << m_line_shift) < config.line_bytes) ++m_line_shift;
    const uint64_t sets = config.lines() / config.ways;
    m_set_mask = sets - 1;
    m_lines.resize(sets * config.ways);
}

bool FunctionalCache::read(uint64_t line, uint32_t bytes, DataKind kind, Cycle now, Cycle* ready, Cycle** fill) {
    MemCounters& c = m_stats[kind];
    ++c.reads;
    c.read_bytes += bytes;
    Line* set = &m_lines[(line & m_set_mask) * m_config.ways];
    Line* victim = set;
    for (uint32_t w = 0; w < m_config.ways; ++w) {
        if (set[w].tag == line) {
            set[w].last_use = ++m_use_clock;
            *ready = set[w].ready;
            ++(set[w].ready > now ? c.merged : c.read_hits);
            return true;
        }
        if (set[w].last_use < victim->last_use) victim = &set[w];
    }
    if (victim->tag != ~0ull) ++m_evictions;
    victim->tag = line;
    victim->last_use = ++m_use_clock;
    *fill = &victim->ready;
    return false;
}

void FunctionalCache::write(uint32_t bytes, DataKind kind) {
    MemCounters& c = m_stats[kind];
    ++c.writes;
    c.write_bytes += bytes;
}

nlohmann::json FunctionalCache::stats_json() const {
    nlohmann::json j;
    StatsWriter(cache_stats(), j)
        .merge(m_stats.to_json())
        .set("evictions", m_evictions)
        .set("mshr_stall_cycles", nullptr)  // no time here
        .set("config", cache_config_json(m_config, nullptr))
        .done();
    return j;
}

}  // namespace rtsim
