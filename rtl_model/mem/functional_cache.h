#pragma once
// A cache with tags, LRU and fill times only: the functional cache simulation of the analytic
// fidelity level. Same geometry, replacement (CacheSets: LRU, invalid lines first) and write policy
// (write-through, no-write-allocate) as Cache, so hit rates agree when accesses come in the
// same order. The caller supplies the time of each access and the fill time of each miss (the
// analytic level's unloaded clocks), so a read of a line still being filled is a merged miss
// as in Cache; there are no MSHR limits, banks or queueing. Pure C++ (no SystemC).
#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "rtl_model/mem/mem_stats.h"
#include "rtl_model/mem/cache_config.h"
#include "rtl_model/mem/cache_sets.h"

namespace rtsim {

class FunctionalCache {
public:
    explicit FunctionalCache(const CacheConfig& config);

    /// Reads line `line` (address >> log2(line_bytes)) at cycle `now`, counting `bytes`. A hit
    /// returns the line's fill time in *ready (a merge when it is after `now`) and true; a miss
    /// allocates the line (LRU victim), returns false, and the caller sets *fill to its fill time.
    bool read(uint64_t line, uint32_t bytes, DataKind kind, Cycle now, Cycle* ready, Cycle** fill);
    /// Counts a write of `bytes` to the line (write-through, no allocate).
    void write(uint32_t bytes, DataKind kind);

    const MemStats& stats() const { return m_stats; }
    uint64_t evictions() const { return m_evictions; }
    uint32_t line_shift() const { return m_line_shift; }
    /// The same keys as Cache::stats_json (mshr_stall_cycles null: no time here).
    nlohmann::json stats_json() const;

private:
    static uint32_t line_shift_of(uint32_t line_bytes);

    CacheConfig m_config;
    uint32_t m_line_shift = 0;
    CacheSets m_sets;            ///< tags and LRU, as Cache keeps them
    std::vector<Cycle> m_ready;  ///< fill cycle per line (sets x ways)
    uint64_t m_evictions = 0;
    MemStats m_stats;
};

}  // namespace rtsim
