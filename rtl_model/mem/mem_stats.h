#pragma once
// Access counters of one memory level, per data kind. Kept in plain arrays in the hot path and
// turned into JSON once at the end (docs/architecture.md, rule 6).
#include <cstdint>

#include <nlohmann/json.hpp>

#include "rtl_model/common/interfaces.h"

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

}  // namespace rtsim
