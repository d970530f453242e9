#pragma once
// Access counters of one memory level, per data kind. Kept in plain arrays in the hot path and
// turned into JSON once at the end (docs/architecture.md, rule 6).
#include <cstdint>

#include <nlohmann/json.hpp>

#include "rtl_model/common/interfaces.h"
#include "rtl_model/common/stats.h"
#include "rtl_model/mem/cache_config.h"
#include "rtl_model/mem/dram_config.h"

namespace rtsim {

struct MemCounters {
    uint64_t reads = 0, writes = 0;
    uint64_t read_hits = 0;       ///< reads served by this level (line present and filled)
    uint64_t merged = 0;          ///< reads of a line still being filled (hit under miss)
    uint64_t read_bytes = 0, write_bytes = 0;

    MemCounters& operator+=(const MemCounters& o) {
        reads += o.reads;
        writes += o.writes;
        read_hits += o.read_hits;
        merged += o.merged;
        read_bytes += o.read_bytes;
        write_bytes += o.write_bytes;
        return *this;
    }
};

class MemStats {
public:
    MemCounters& operator[](DataKind k) { return m_kinds[size_t(k)]; }
    const MemCounters& operator[](DataKind k) const { return m_kinds[size_t(k)]; }
    MemCounters total() const;
    /// {"reads", "writes", "hit_rate", "read_bytes", ..., "by_kind": {...}}
    nlohmann::json to_json() const;

private:
    MemCounters m_kinds[kDataKindCount];
};

/// The stats of the memory levels, declared once; every level and the analytic level write
/// through them. A cache (model.l1.<l1>, model.l2):
const StatBlock& cache_stats();
/// DRAM (model.dram), the bank model's counters optional:
const StatBlock& dram_stats();
/// Ideal memory (model.ideal_memory):
const StatBlock& ideal_memory_stats();

/// A memory level's counters as DRAM reports them: DRAM serves every read, so hit rates and
/// merges mean nothing there and are left out (at the top and per kind).
nlohmann::json dram_counters_json(const MemStats& stats);
/// A cache's `config` stats: its geometry and the MSHRs modelled (null where none are).
nlohmann::json cache_config_json(const CacheConfig& c, const nlohmann::json& mshrs);
/// DRAM's bandwidth stats (bandwidth_gbps, peak_bandwidth_gbps, bandwidth_utilization) for
/// `bytes` moved in `cycles` at `clock_ghz`.
void dram_bandwidth_stats(StatsWriter& w, const DramConfig& c, double bytes, double cycles, double clock_ghz);

}  // namespace rtsim
