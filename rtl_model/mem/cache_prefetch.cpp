// Prefetches in a cache (treelet prefetching, Chou, Nowicki & Aamodt 2023; docs/treelets.md,
// "Prefetching"). A prefetch is a read nobody waits for. Above its target level it is passed
// down; at its target it allocates the line like a miss, but only into an MSHR free at its issue
// cycle: demand misses keep priority, and a prefetcher that finds none retries when one frees
// (the cycle returned). Each prefetched line is then counted exactly once: used by a read
// (useful; `late` when the read came while it was still being filled), evicted unused
// (useless), or still resident at the end, so issued = useful + useless + resident.
// Prefetches hold at most half the MSHRs at once (kPrefetchMshrShare), so a long treelet
// prefetch never takes every MSHR from the demand misses that follow it.
#include <algorithm>

#include "rtl_model/mem/cache.h"

namespace rtsim {

namespace {
constexpr uint32_t kPrefetchMshrShare = 2;  ///< prefetches may hold 1 / this of the MSHRs
}  // namespace

Cycle Cache::prefetch(const MemRequest& req) {
    if (m_level < req.prefetch_into) {
        MemRequest down = req;
        down.time = req.time + m_next_latency;
        const Cycle retry = next->access(down);
        return retry > down.time ? retry - m_next_latency : req.time;
    }
    m_prefetch_seen = true;
    const uint64_t line = req.addr >> m_line_shift;
    if (m_sets.find(line) != CacheSets::kNoWay) {
        ++m_prefetch.redundant;  // present or being filled: nothing to fetch
        return req.time;
    }
    if (!m_prefetch_mshrs)
        m_prefetch_mshrs = std::make_unique<MinTree>(std::max<uint32_t>(1, m_config.mshrs / kPrefetchMshrShare), 0);
    Cycle free = m_prefetch_mshrs->top_time();
    if (m_mshrs_enabled) free = std::max(free, m_mshr_free.top_time());
    if (free > req.time) {
        ++m_prefetch.blocked;
        return free;
    }
    if (m_mshr_backfill) {
        const Cycle start = m_mshr_backfill->earliest(req.time, Cycle(m_expected_miss)).start;
        if (start > req.time) {
            ++m_prefetch.blocked;
            return start;
        }
    }
    if (m_prefetched.empty()) m_prefetched.assign(m_fills.size(), 0);
    const Cycle bank = bank_start(line, req.time);
    m_bank_use.add(bank, 1);
    ++m_prefetch.issued;
    const Cycle fill = miss(line, req, bank + m_config.latency, nullptr);
    m_prefetch_mshrs->set(m_prefetch_mshrs->top(), fill);
    return req.time;
}

void Cache::prefetch_used(size_t way, bool late) {
    m_prefetched[way] = 0;
    ++m_prefetch.useful;
    if (late) ++m_prefetch.late;
}

nlohmann::json Cache::prefetch_json() const {
    const uint64_t resident = uint64_t(std::count(m_prefetched.begin(), m_prefetched.end(), uint8_t(1)));
    return {{"issued", m_prefetch.issued},       {"redundant", m_prefetch.redundant}, {"blocked", m_prefetch.blocked},
            {"useful", m_prefetch.useful},       {"late", m_prefetch.late},           {"useless", m_prefetch.useless},
            {"resident", resident},              {"below_bytes", m_prefetch.below_bytes}};
}

}  // namespace rtsim
