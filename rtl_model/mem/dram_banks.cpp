#include "rtl_model/mem/dram_banks.h"

#include <algorithm>

namespace rtsim {

DramBanks::DramBanks(const DramConfig& config)
    : m_config(config), m_close_page(config.page_policy == PagePolicy::close), m_banks(size_t(config.channels) * config.banks) {
    for (uint32_t c = 0; c < config.channels; ++c) m_buses.emplace_back(config.bytes_per_cycle, 1);
}

DramAddress DramBanks::map(uint64_t addr) const {
    const uint64_t granule = addr / m_config.interleave_bytes;
    DramAddress a;
    a.channel = uint32_t(granule % m_config.channels);
    const uint64_t local = (granule / m_config.channels) * m_config.interleave_bytes + addr % m_config.interleave_bytes;
    a.column = uint32_t(local % m_config.row_bytes);
    a.bank = uint32_t((local / m_config.row_bytes) % m_config.banks);
    a.row = local / m_config.row_bytes / m_config.banks;
    return a;
}

Cycle DramBanks::to_column(RowResult r) const {
    switch (r) {
        case RowResult::hit: return 0;
        case RowResult::miss: return m_config.t_rcd;
        case RowResult::conflict: return Cycle(m_config.t_rp) + m_config.t_rcd;
    }
    return 0;
}

uint32_t DramBanks::Bank::upper_bound(Cycle time) {
    // Usually the answer is the end: look there first, then bisect.
    if (size == 0 || at(size - 1).start <= time) return size;
    uint32_t lo = 0, hi = size - 1;  // at(hi).start > time
    while (lo < hi) {
        const uint32_t mid = (lo + hi) / 2;
        if (at(mid).start > time) hi = mid;
        else lo = mid + 1;
    }
    return lo;
}

void DramBanks::Bank::insert(uint32_t i, const Booking& b) {
    for (uint32_t k = size; k > i; --k) at(k) = at(k - 1);
    at(i) = b;
    ++size;
    if (size > kKept) {  // forget the oldest (requests never arrive that far out of order)
        base_row = at(0).row;
        head = (head + 1) & (kRing - 1);
        --size;
    }
}

DramBanks::Timing DramBanks::access(uint64_t addr, uint32_t bytes, Cycle time) {
    const DramAddress a = map(addr);
    Bank& bank = m_banks[size_t(a.channel) * m_config.banks + a.bank];
    const uint32_t bpc = m_config.bytes_per_cycle;
    const Cycle burst = (std::max<uint32_t>(bytes, 1) + bpc - 1) / bpc;
    const Cycle tail = burst + (m_close_page ? m_config.t_rp : 0);  // after the column command
    auto outcome = [&](uint64_t open) {
        if (open == a.row && !m_close_page) return RowResult::hit;
        return open == kClosed ? RowResult::miss : RowResult::conflict;
    };
    // The first idle gap at or after `time` long enough for this access, given the row the
    // access before it leaves open.
    uint32_t next = bank.upper_bound(time);
    uint64_t open = bank.base_row;
    Cycle s = time;
    if (next > 0) {
        const Booking& prev = bank.at(next - 1);
        open = prev.row;
        s = std::max(s, prev.end);
    }
    RowResult result = outcome(open);
    for (; next < bank.size && s + to_column(result) + tail > bank.at(next).start; ++next) {
        s = std::max(s, bank.at(next).end);
        open = bank.at(next).row;
        result = outcome(open);
    }
    Timing t;
    t.start = s;
    t.result = result;
    t.column = s + to_column(result);
    bank.insert(next, Booking{s, t.column + tail, m_close_page ? kClosed : a.row});
    // The burst takes the first free cycles of the channel's data bus from column + tCAS.
    SlotCalendar& bus = m_buses[a.channel];
    Cycle cycle = t.column + m_config.t_cas;
    uint32_t left = std::max<uint32_t>(bytes, 1);
    for (Cycle i = 0; i < burst; ++i) {
        const uint32_t chunk = std::min(left, bpc);
        cycle = bus.reserve(cycle, chunk) + 1;
        left -= chunk;
    }
    t.done = cycle;
    ++bank.counts[size_t(result)];
    ++m_totals[size_t(result)];
    return t;
}

nlohmann::json DramBanks::stats_json() const {
    const uint64_t all = m_totals[0] + m_totals[1] + m_totals[2];
    nlohmann::json by_bank = nlohmann::json::array();
    for (size_t i = 0; i < m_banks.size(); ++i) {
        const Bank& b = m_banks[i];
        const uint64_t n = b.counts[0] + b.counts[1] + b.counts[2];
        if (!n) continue;
        by_bank.push_back({{"channel", i / m_config.banks}, {"bank", i % m_config.banks}, {"accesses", n},
                           {"row_hits", b.counts[0]}, {"row_misses", b.counts[1]}, {"row_conflicts", b.counts[2]}});
    }
    return {{"row_hits", m_totals[0]},
            {"row_misses", m_totals[1]},
            {"row_conflicts", m_totals[2]},
            {"row_hit_rate", all ? double(m_totals[0]) / double(all) : 0.0},
            {"page_policy", kPagePolicyChoices.name(m_config.page_policy)},
            {"banks_per_channel", m_config.banks},
            {"row_bytes", m_config.row_bytes},
            {"by_bank", by_bank}};
}

}  // namespace rtsim
