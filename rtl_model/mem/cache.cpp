#include "rtl_model/mem/cache.h"

#include <algorithm>

namespace rtsim {

namespace {
uint32_t log2_exact(uint64_t x) {
    uint32_t s = 0;
    while ((1ull << s) < x) ++s;
    return s;
}
}  // namespace

Cache::Cache(sc_core::sc_module_name name, const CacheConfig& config, bool mshrs_enabled, Cycle next_latency,
             bool exact, ServedBy level)
    : sc_core::sc_module(name),
      m_config(config),
      m_level(level),
      m_mshrs_enabled(mshrs_enabled),
      m_next_latency(next_latency),
      m_line_shift(log2_exact(config.line_bytes)),
      m_sets(config.lines() / config.ways, config.ways, m_line_shift),
      m_mshr_free(config.mshrs, 0),
      m_bank_of(config.banks) {
    m_fills.resize(config.lines());
    // Each bank serves one access per bank_cycles; the calendar counts them per 16-access window
    // (a finer window only makes the forward search longer when a bank is busy).
    // The detailed level reserves single accesses exactly (one per bank_cycles, no fast path).
    for (uint32_t b = 0; b < config.banks; ++b) {
        if (exact) m_exact_banks.emplace_back(1, config.bank_cycles);
        else m_banks.emplace_back(16, 16 * config.bank_cycles);
    }
    m_bank_always_free = !exact && config.banks == 1 && config.bank_cycles == 1;
}

Cycle Cache::access(const MemRequest& req) {
    if (req.prefetch && uint8_t(m_level) <= uint8_t(req.prefetch_into)) return prefetch(req);
    uint64_t first = req.addr >> m_line_shift;
    uint64_t last = (req.addr + (req.bytes ? req.bytes : 1) - 1) >> m_line_shift;
    // One line (most node and triangle fetches): where its time went is the line's own.
    if (first == last) {
        if (req.info) *req.info = AccessInfo{};
        return std::max(req.time, access_line(first, req, req.info));
    }
    Cycle done = req.time;
    if (!req.info) {
        for (uint64_t line = first; line <= last; ++line) done = std::max(done, access_line(line, req, nullptr));
        return done;
    }
    // The read's time is that of its slowest line: report where that line's time went.
    for (uint64_t line = first; line <= last; ++line) {
        AccessInfo line_info;
        const Cycle ready = access_line(line, req, &line_info);
        if (line == first || ready > done) {
            done = std::max(done, ready);
            *req.info = line_info;
        }
    }
    return done;
}

void Cache::prefetch_host(uint64_t addr) const {
    m_sets.prefetch(m_sets.set_of(addr >> m_line_shift));
    if (m_next_cache) m_next_cache->prefetch_host(addr);  // the L2's set, for an L1 miss
}

Cycle Cache::forward(const MemRequest& down) {
    if (!m_next_resolved) {
        m_next_cache = dynamic_cast<Cache*>(next.get_interface());
        m_next_dram = dynamic_cast<Dram*>(next.get_interface());
        m_next_resolved = true;
    }
    if (m_next_cache) return m_next_cache->access(down);
    if (m_next_dram) return m_next_dram->access(down);
    return next->access(down);
}

Cycle Cache::reserve_bank(uint64_t line, Cycle time) {
    if (!m_exact_banks.empty()) return m_exact_banks[m_bank_of.mod(line)].reserve(time, 1);
    return m_banks[m_bank_of.mod(line)].reserve(time, 1);
}

Cycle Cache::access_line(uint64_t line, const MemRequest& req, AccessInfo* info) {
    const uint64_t line_lo = line << m_line_shift, line_hi = line_lo + m_config.line_bytes;
    const uint64_t lo = std::max(req.addr, line_lo), hi = std::min(req.addr + req.bytes, line_hi);
    const uint32_t bytes = uint32_t(hi > lo ? hi - lo : 0);
    MemCounters& c = m_stats[req.kind];
    const Cycle bank = bank_start(line, req.time);
    m_bank_use.add(bank, 1);
    Cycle tag_done = bank + m_config.latency;

    if (req.write) {
        // Write-through, no-write-allocate, posted.
        ++c.writes;
        c.write_bytes += bytes;
        MemRequest down = req;
        down.addr = lo;
        down.bytes = bytes;
        down.time = tag_done + m_next_latency;
        down.info = nullptr;
        forward(down);
        return tag_done;
    }
    ++c.reads;
    c.read_bytes += bytes;
    const uint32_t way = m_sets.find(line);
    if (way == CacheSets::kNoWay) return miss(line, req, tag_done, info);
    const uint64_t set = m_sets.set_of(line);
    m_sets.touch(set, way);
    const size_t index = size_t(set) * m_config.ways + way;
    // The line's fill record is read only when some fill of its set may still be in flight.
    const bool set_filling = m_sets.latest_fill(set) > tag_done;
    const LineFill* in_flight = set_filling && m_fills[index].ready > tag_done ? &m_fills[index] : nullptr;
    if (!m_prefetched.empty() && m_prefetched[index]) prefetch_used(index, in_flight != nullptr);
    if (in_flight) {
        ++c.merged;
        if (info) info->level = in_flight->filled_from;  // waits for a fill in flight
        return in_flight->ready;
    }
    ++c.read_hits;
    if (info) info->level = m_level;
    return tag_done;
}

Cycle Cache::miss(uint64_t line, const MemRequest& req, Cycle tag_done, AccessInfo* info) {
    Cycle issue = tag_done;
    uint32_t mshr = 0;
    if (m_mshrs_enabled) {
        mshr = m_mshr_free.top();  // the earliest free (the lowest index among equals)
        if (m_mshr_free.top_time() > issue) {
            m_mshr_stall_cycles += m_mshr_free.top_time() - issue;
            issue = m_mshr_free.top_time();
        }
    }
    const Cycle stamped = issue;
    if (m_mshr_backfill) {
        // Requests out of time order: the MSHR that can take a miss of the usual length soonest.
        const BackfillSlots::Pick pick = m_mshr_backfill->earliest(issue, Cycle(m_expected_miss));
        m_mshr_stall_cycles += pick.start - issue;
        issue = pick.start;
        mshr = pick.slot;
    }
    if (info) info->mshr_wait[size_t(m_level)] += issue - tag_done;
    AccessInfo below;
    MemRequest down{line << m_line_shift, m_config.line_bytes, false, req.kind, issue + m_next_latency, &below,
                    req.prefetch, req.prefetch_into};
    Cycle fill = forward(down) + m_next_latency;
    if (info) {
        info->level = below.level;
        for (int k = 0; k < 2; ++k) info->mshr_wait[k] += below.mshr_wait[k];
    }
    m_mshr_busy_cycles += fill - issue;
    m_mshr_use.add_interval(issue, fill);
    if (m_mshrs_enabled) m_mshr_free.set(mshr, fill);
    if (m_mshr_backfill) {
        m_mshr_backfill->book(mshr, stamped, issue, fill);
        m_expected_miss += (double(fill - issue) - m_expected_miss) / 64.0;  // running mean
    }

    // LRU victim (never-used ways go first).
    const uint64_t set = m_sets.set_of(line);
    const uint32_t way = m_sets.victim(set);
    const size_t victim = size_t(set) * m_config.ways + way;
    if (m_sets.valid(set, way)) ++m_evictions;
    if (req.prefetch) {
        m_prefetch_seen = true;
        m_prefetch.below_bytes += m_config.line_bytes;  // traffic below this level caused by prefetching
    }
    if (!m_prefetched.empty()) {
        if (m_prefetched[victim]) ++m_prefetch.useless;  // evicted before any read used it
        m_prefetched[victim] = req.prefetch && req.prefetch_into == m_level;
    }
    m_sets.place(way, line);
    m_sets.note_fill(set, fill);
    m_fills[victim] = {fill, below.level};
    return fill;
}

bool Cache::warm(uint64_t addr, uint32_t bytes) {
    bool hit = true;
    const uint64_t last = (addr + std::max<uint32_t>(bytes, 1) - 1) >> m_line_shift;
    for (uint64_t line = addr >> m_line_shift; line <= last; ++line) {
        const uint64_t set = m_sets.set_of(line);
        const uint32_t way = m_sets.find(line);
        if (way != CacheSets::kNoWay) {
            m_sets.touch(set, way);
            continue;
        }
        hit = false;
        const uint32_t victim = m_sets.victim(set);
        m_sets.place(victim, line);
        m_fills[size_t(set) * m_config.ways + victim] = {0, m_level};
    }
    return hit;
}

void Cache::backfill_misses() {
    m_mshr_backfill = std::make_unique<BackfillSlots>(m_config.mshrs);
    m_expected_miss = double(2 * m_next_latency + m_config.latency + 100);  // first guess, then learnt
}


nlohmann::json Cache::stats_json(Cycle total_cycles, bool series) const {
    nlohmann::json j;
    StatsWriter w(cache_stats(), j);
    w.merge(m_stats.to_json());
    w.set("evictions", m_evictions);
    w.set("mshr_stall_cycles", m_mshr_stall_cycles);
    w.set("mshr_busy_cycles", m_mshr_busy_cycles);
    const double cycles = double(std::max<Cycle>(total_cycles, 1));
    uint64_t accesses = 0;
    for (uint64_t b : m_bank_use.buckets()) accesses += b;
    w.set("bank_utilization", double(accesses) / cycles / bank_capacity());
    w.set("mshr_occupancy", double(m_mshr_busy_cycles) / cycles);  // mean outstanding misses
    w.set("mshr_utilization", double(m_mshr_busy_cycles) / cycles / m_config.mshrs);
    if (series) {
        w.set("bank_utilization_over_time", m_bank_use.to_json(bank_capacity()));
        w.set("mshr_utilization_over_time", m_mshr_use.to_json(double(m_config.mshrs)));
    }
    const uint32_t mshrs = (m_mshrs_enabled || m_mshr_backfill) ? m_config.mshrs : 0u;
    w.set("config", cache_config_json(m_config, mshrs));
    if (m_prefetch_seen) w.set("prefetch", prefetch_json());
    w.done();
    return j;
}

}  // namespace rtsim
