#pragma once
// A set-associative cache with LRU replacement, MSHRs, banks and a latency, as a SystemC
// channel implementing MemIf; misses go to `next` (the L2 or DRAM).
//
// Reads: a hit returns after the hit latency (or when a line still being filled arrives: a merged
// miss). A miss takes the earliest free MSHR (waiting if all are busy), goes to the next level
// after the tag latency, allocates the line at once (LRU victim) and holds the MSHR until the fill.
// Writes are write-through and no-write-allocate (ray hits and stack spills are written once and
// not read back soon); they are posted: the issuer does not wait beyond the tag access.
// MSHRs are a free list when one issuer accesses the cache in time order (a private L1); a
// shared cache reached out of time order (the L2) keeps each MSHR's booked intervals instead
// (backfill_misses). At the detailed level (exact = true) banks are per-cycle slot calendars
// (one access per bank_cycles, arrival order at equal cycles) instead of 16-access windows.
// Prefetches (treelet prefetching, cache_prefetch.cpp) allocate a line without a waiter, only
// into a free MSHR, and are counted until a read uses the line or it is evicted unused.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <systemc>

#include "rtl_model/common/backfill_slots.h"
#include "rtl_model/common/calendar.h"
#include "rtl_model/common/min_tree.h"
#include "rtl_model/common/usage_series.h"
#include "rtl_model/mem/mem_stats.h"
#include "rtl_model/mem/cache_config.h"
#include "rtl_model/mem/cache_sets.h"
#include "rtl_model/mem/dram.h"

namespace rtsim {

class Cache : public sc_core::sc_module, public MemIf {
public:
    sc_core::sc_port<MemIf> next;

    /// next_latency: cycles added to every request forwarded to `next` and back (interconnect).
    /// level: which level this cache is (what AccessInfo reports for reads it serves).
    Cache(sc_core::sc_module_name name, const CacheConfig& config, bool mshrs_enabled, Cycle next_latency,
          bool exact = false, ServedBy level = ServedBy::l1);

    Cycle access(const MemRequest& req) final;
    /// Prefetches the host memory of the set `addr` maps to (its tags and LRU stamps), here and
    /// in the next level when it is a cache.
    void prefetch_host(uint64_t addr) const final;
    /// Functional warming (sampling, SMARTS): makes the lines of [addr, addr + bytes) present and
    /// most recently used, as a read would, with no time, no stats and no traffic below.
    /// Returns true when every line was already present (a hit: the level below would not see it).
    bool warm(uint64_t addr, uint32_t bytes);
    uint32_t line_bytes() const { return m_config.line_bytes; }
    /// For a shared cache reached out of time order (the L2: within a quantum at approx, and at
    /// both timed levels for an L1 miss that waited for its MSHR, stamped with the cycle it
    /// frees): MSHRs that an earlier-stamped request takes while idle before later bookings
    /// (backfill_slots.h).
    void backfill_misses();

    const MemStats& stats() const { return m_stats; }
    /// MSHR-cycles held by misses (sum over misses of issue to fill): Little's law demand.
    uint64_t mshr_busy_cycles() const { return m_mshr_busy_cycles; }
    /// Stats; utilisation of banks and MSHRs over `total_cycles` (and over time, with `series`).
    nlohmann::json stats_json(Cycle total_cycles, bool series = false) const;
    const UsageSeries& bank_use() const { return m_bank_use; }
    const UsageSeries& mshr_use() const { return m_mshr_use; }
    /// Line accesses the banks can serve per cycle, and MSHRs: the capacities of the two series.
    double bank_capacity() const { return double(m_config.banks) / m_config.bank_cycles; }
    uint32_t mshrs() const { return m_config.mshrs; }

private:
    /// Prefetch counters (cache_prefetch.cpp): issued = useful + useless + still resident.
    struct PrefetchCounters {
        uint64_t issued = 0, redundant = 0, blocked = 0, useful = 0, late = 0, useless = 0, below_bytes = 0;
    };
    /// A prefetch reaching this level: passed down above its target, allocated at it.
    Cycle prefetch(const MemRequest& req);
    /// A read found a prefetched line (way) not used before: the prefetch was useful.
    void prefetch_used(size_t way, bool late);
    nlohmann::json prefetch_json() const;
    /// A line's state besides its tag and LRU stamp (read only on a hit or a fill).
    struct LineFill {
        Cycle ready = 0;                      ///< cycle the fill completes
        ServedBy filled_from = ServedBy::l1;  ///< where its fill came from (for merged reads)
    };
    /// A request to the next level: a direct call when it is a Cache or the Dram (the usual
    /// L1 -> L2 -> DRAM chain, resolved on first use), else through the port.
    Cycle forward(const MemRequest& down);
    Cycle access_line(uint64_t line_addr, const MemRequest& req, AccessInfo* info);
    Cycle miss(uint64_t line_addr, const MemRequest& req, Cycle tag_done, AccessInfo* info);
    /// Cycle the line's bank takes an access arriving at `time` (at once with one bank serving
    /// an access per cycle, the L1s' default: no calendar then).
    Cycle bank_start(uint64_t line_addr, Cycle time) { return m_bank_always_free ? time : reserve_bank(line_addr, time); }
    Cycle reserve_bank(uint64_t line_addr, Cycle time);

    CacheConfig m_config;
    ServedBy m_level;
    bool m_next_resolved = false;
    Cache* m_next_cache = nullptr;
    Dram* m_next_dram = nullptr;
    bool m_mshrs_enabled;
    Cycle m_next_latency;
    uint32_t m_line_shift;
    // Tags and LRU state packed set by set (cache_sets.h: a lookup touches its set's one or two
    // host lines); the fill records, sets x ways, are read only on a miss or a fill in flight.
    CacheSets m_sets;
    std::vector<LineFill> m_fills;
    MinTree m_mshr_free;  ///< cycle each MSHR is free again; the earliest is the next one used
    std::unique_ptr<BackfillSlots> m_mshr_backfill;  ///< MSHRs reached out of time order (the L2)
    double m_expected_miss = 0;                           ///< running mean of miss durations
    Divider m_bank_of;  ///< line -> bank (line-interleaved)
    std::vector<BandwidthCalendar> m_banks;
    std::vector<SlotCalendar> m_exact_banks;  ///< detailed level only
    bool m_bank_always_free = false;          ///< one bank, one access per cycle, not exact
    MemStats m_stats;
    uint64_t m_evictions = 0;
    uint64_t m_mshr_stall_cycles = 0;  ///< request-cycles waited for an MSHR (summed over misses)
    uint64_t m_mshr_busy_cycles = 0;   ///< MSHR-cycles held by misses
    UsageSeries m_bank_use;            ///< line accesses over time
    UsageSeries m_mshr_use;            ///< MSHR-cycles held over time
    std::vector<uint8_t> m_prefetched;  ///< per way: filled by a prefetch, not yet read (sized at the first prefetch)
    PrefetchCounters m_prefetch;
    std::unique_ptr<MinTree> m_prefetch_mshrs;  ///< fill cycle of each MSHR prefetches may hold (half of them)
    bool m_prefetch_seen = false;       ///< a prefetch (or a miss for one above) reached this level
};

}  // namespace rtsim
