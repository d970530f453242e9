#include "rtl_model/mem/functional_cache.h"

namespace rtsim {

uint32_t FunctionalCache::line_shift_of(uint32_t line_bytes) {
    uint32_t shift = 0;
    while ((1u << shift) < line_bytes) ++shift;
    return shift;
}

FunctionalCache::FunctionalCache(const CacheConfig& config)
    : m_config(config),
      m_line_shift(line_shift_of(config.line_bytes)),
      m_sets(config.lines() / config.ways, config.ways, m_line_shift),
      m_ready(config.lines(), 0) {}

bool FunctionalCache::read(uint64_t line, uint32_t bytes, DataKind kind, Cycle now, Cycle* ready, Cycle** fill) {
    MemCounters& c = m_stats[kind];
    ++c.reads;
    c.read_bytes += bytes;
    const uint64_t set = m_sets.set_of(line);
    const uint32_t way = m_sets.find(line);
    if (way != CacheSets::kNoWay) {
        m_sets.touch(set, way);
        *ready = m_ready[set * m_config.ways + way];
        ++(*ready > now ? c.merged : c.read_hits);
        return true;
    }
    const uint32_t victim = m_sets.victim(set);
    if (m_sets.valid(set, victim)) ++m_evictions;
    m_sets.place(victim, line);
    *fill = &m_ready[set * m_config.ways + victim];
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
