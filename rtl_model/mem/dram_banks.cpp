#include "rtl_model/mem/dram_banks.h"

#include <algorithm>

namespace rtsim {

DramBanks::DramBanks(const DramConfig& config)
    : m_config(config),
      m_close_page(config.page_policy == PagePolicy::close),
      m_column_limits(config.t_ccd_l || config.t_wtr || config.t_wtr_l || config.t_rtw),
      m_frfcfs(config.scheduler == DramScheduler::frfcfs && config.page_policy == PagePolicy::open),
      m_banks(size_t(config.channels) * config.banks) {
    for (uint32_t c = 0; c < config.channels; ++c) m_buses.emplace_back(config.bytes_per_cycle, 1);
    m_activates.resize(config.channels);
    m_columns.resize(config.channels);
    if (config.queue_entries)
        for (uint32_t c = 0; c < config.channels; ++c) m_queues.emplace_back(config.queue_entries);
}

DramAddress DramBanks::map(uint64_t addr) const {
    const uint64_t granule = addr / m_config.interleave_bytes;
    DramAddress a;
    a.channel = uint32_t(granule % m_config.channels);
    const uint64_t local = (granule / m_config.channels) * m_config.interleave_bytes + addr % m_config.interleave_bytes;
    const uint32_t gi = m_config.group_interleave_bytes, groups = m_config.bank_groups;
    if (gi == 0 || groups == 1) {
        a.column = uint32_t(local % m_config.row_bytes);
        a.bank = uint32_t((local / m_config.row_bytes) % m_config.banks);
        a.group = a.bank % groups;
        a.row = local / m_config.row_bytes / m_config.banks;
        return a;
    }
    // Granule k of the channel goes to group k mod G; within a group its bytes fill rows of the
    // group's banks in turn, as a channel's bytes fill its banks without interleaving (a
    // bijection: group, bank in group, row and column give the address back).
    const uint64_t k = local / gi;
    a.group = uint32_t(k % groups);
    const uint64_t in_group = (k / groups) * gi + local % gi;
    const uint32_t per_group = m_config.banks / groups;
    a.column = uint32_t(in_group % m_config.row_bytes);
    a.bank = uint32_t((in_group / m_config.row_bytes) % per_group) * groups + a.group;
    a.row = in_group / m_config.row_bytes / per_group;
    return a;
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
        base_activated = at(0).activated;
        base_end = at(0).end;
        head = (head + 1) & (kRing - 1);
        --size;
    }
}

namespace {
constexpr size_t kActivatesKept = 32;  ///< per channel, for tRRD and tFAW
constexpr size_t kColumnsKept = 32;    ///< per channel, for tCCD_L, tWTR and tRTW
}

Cycle DramBanks::first_activate(uint32_t c, uint32_t group, Cycle at) const {
    const Cycle rrd = m_config.t_rrd, rrd_l = std::max(m_config.t_rrd, m_config.t_rrd_l), faw = m_config.t_faw;
    if (rrd_l == 0 && faw == 0) return at;
    const std::vector<Activate>& acts = m_activates[c];
    for (;;) {
        bool moved = false;
        for (const Activate& x : acts) {
            const Cycle sep = x.group == group ? rrd_l : rrd;
            if (x.at + sep > at && at + sep > x.at) {  // within tRRD (tRRD_L in one group) of another activate
                at = x.at + sep, moved = true;
                break;
            }
        }
        if (moved) continue;
        if (faw) {
            // Every window of tFAW cycles that would hold this activate: starting at it, or at an
            // earlier activate less than tFAW before it. Four others in one: move past it.
            auto others_in = [&](Cycle w) {
                int n = 0;
                for (const Activate& x : acts) n += x.at >= w && x.at < w + faw;
                return n;
            };
            if (others_in(at) >= 4) at += 1, moved = true;
            for (size_t i = 0; !moved && i < acts.size(); ++i)
                if (acts[i].at <= at && acts[i].at + faw > at && others_in(acts[i].at) >= 4)
                    at = acts[i].at + faw, moved = true;
        }
        if (!moved) return at;
    }
}

void DramBanks::record_activate(uint32_t c, uint32_t group, Cycle at) {
    if (m_config.t_rrd == 0 && m_config.t_rrd_l == 0 && m_config.t_faw == 0) return;
    std::vector<Activate>& acts = m_activates[c];
    const auto later = std::upper_bound(acts.begin(), acts.end(), at, [](Cycle t, const Activate& x) { return t < x.at; });
    acts.insert(later, Activate{at, group});
    if (acts.size() > kActivatesKept) acts.erase(acts.begin());
}

Cycle DramBanks::first_column(uint32_t c, uint32_t group, bool write, Cycle burst, Cycle at) const {
    if (!m_column_limits) return at;
    const Cycle ccd = m_config.t_ccd_l, rtw = m_config.t_rtw, cas = m_config.t_cas;
    const Cycle wtr_s = m_config.t_wtr, wtr_l = m_config.t_wtr_l ? m_config.t_wtr_l : m_config.t_wtr;
    for (;;) {
        bool moved = false;
        for (const Column& x : m_columns[c]) {
            // The least distance from x to this command when it follows x (`after`) and from it
            // to x when it precedes x (`before`); a command strictly between is moved past x.
            // Write to read within one bank group: tWTR_L; across groups: tWTR_S.
            const Cycle wtr = x.group == group ? wtr_l : wtr_s;
            Cycle after = x.group == group ? ccd : 0, before = after;
            if (x.write && !write && wtr) after = std::max(after, cas + x.burst + wtr);   // read after a write's data
            if (x.write && !write && rtw) before = std::max(before, rtw);                // read, then the write
            if (!x.write && write && rtw) after = std::max(after, rtw);                  // write after a read
            if (!x.write && write && wtr) before = std::max(before, cas + burst + wtr);  // write's data, then the read
            // Issued at x's cycle or later it follows x (x was booked first).
            const bool conflict = at >= x.at ? at < x.at + after : at + before > x.at;
            if (conflict) {
                at = x.at + after, moved = true;
                break;
            }
        }
        if (!moved) return at;
    }
}

void DramBanks::record_column(uint32_t c, uint32_t group, bool write, Cycle burst, Cycle at) {
    if (!m_column_limits) return;
    std::vector<Column>& cols = m_columns[c];
    const auto later = std::upper_bound(cols.begin(), cols.end(), at, [](Cycle t, const Column& x) { return t < x.at; });
    cols.insert(later, Column{at, group, write, burst});
    if (cols.size() > kColumnsKept) cols.erase(cols.begin());
}

DramBanks::Timing DramBanks::plan(const DramAddress& a, Cycle s, OpenRow open, Cycle burst, bool write,
                                  Cycle* end, Cycle* activate) const {
    const Cycle refi = m_config.t_refi, rfc = m_config.t_rfc;
    Timing t;
    bool deferred = false;  // past one refresh already: a gap too short for it does not defer it again
    for (;;) {
        if (refi) {
            // Refreshes at k x tREFI (k >= 1), tRFC long: start after one under way; a refresh
            // since the bank went idle closed its row.
            const Cycle last = s / refi * refi;
            if (last >= refi && s < last + rfc) t.refresh_wait += last + rfc - s, s = last + rfc;
            if (last >= refi && last >= open.idle_since) open.row = kClosed;
        }
        t.result = open.row == kClosed ? RowResult::miss
                   : open.row == a.row && !m_close_page ? RowResult::hit
                                                        : RowResult::conflict;
        Cycle act = kNoActivate;
        t.ras_wait = t.activate_wait = t.column_wait = 0;
        if (t.result == RowResult::hit) {
            t.column = s;
        } else {
            Cycle want = s;
            if (t.result == RowResult::conflict) {
                // An access back-filled before the booking that left the row open (far out of
                // order) has no activate before it to count tRAS from.
                const Cycle precharge =
                    open.activated <= s ? std::max<Cycle>(s, open.activated + m_config.t_ras) : s;
                t.ras_wait = precharge - s;
                want = precharge + m_config.t_rp;
            }
            act = first_activate(a.channel, a.group, want);
            t.activate_wait = act - want;
            t.column = act + m_config.t_rcd;
        }
        const Cycle column = first_column(a.channel, a.group, write, burst, t.column);
        t.column_wait = column - t.column;
        t.column = column;
        Cycle finish = t.column + burst;
        if (m_close_page) {  // auto-precharge, no sooner than tRAS after the activate
            const Cycle precharge = std::max<Cycle>(finish, act == kNoActivate ? 0 : act + m_config.t_ras);
            finish = precharge + m_config.t_rp;
        }
        if (refi) {
            const Cycle next = (s / refi + 1) * refi;
            if (finish > next && !deferred) {  // would run into the next refresh: after it, row closed
                deferred = true;
                t.refresh_wait += next + rfc - s;
                s = next + rfc;
                open.row = kClosed;
                continue;
            }
        }
        t.start = s;
        *end = finish;
        *activate = act;
        return t;
    }
}

bool DramBanks::row_hit_first(Bank& bank, const DramAddress& a, Cycle time, Cycle burst, bool write, Timing* t) {
    // Before booking p (p >= the first booked after `time`) the row is a.row, and booking p
    // leaves another open (a conflict, or a refresh's miss): the scheduler, holding this
    // request since `time`, would pick it first there. At the end of the bookings FCFS does.
    const uint32_t first = bank.upper_bound(time);
    uint32_t p = first;
    auto row_before = [&](uint32_t i) { return i > 0 ? bank.at(i - 1).row : bank.base_row; };
    while (p < bank.size && !(row_before(p) == a.row && bank.at(p).row != a.row)) ++p;
    if (p >= bank.size) return false;
    const Cycle idle = p > 0 ? bank.at(p - 1).end : bank.base_end;
    const Cycle activated = p > 0 ? bank.at(p - 1).activated : bank.base_activated;
    Cycle end = 0, act = kNoActivate;
    const Timing planned = plan(a, std::max(time, idle), OpenRow{a.row, activated, idle}, burst, write, &end, &act);
    if (planned.result != RowResult::hit) return false;  // a refresh closed the row first
    *t = planned;
    const bool forgets = bank.size == Bank::kKept;  // insert() then forgets the oldest booking
    bank.insert(p, Booking{planned.start, end, a.row, activated});
    ++m_hits_first;
    // The bookings it passes move back as far as it overlaps them (their gaps absorb it).
    uint32_t i = p + 1 - (forgets ? 1 : 0);
    for (Cycle prev_end = end; i < bank.size && bank.at(i).start < prev_end; ++i) {
        Booking& b = bank.at(i);
        const Cycle shift = prev_end - b.start;
        if (b.activated >= b.start) b.activated += shift;  // its own activate moves with it
        b.start += shift, b.end += shift;
        m_moved_back += shift;
        prev_end = b.end;
    }
    return true;
}

DramBanks::Timing DramBanks::access(uint64_t addr, uint32_t bytes, Cycle time, bool write) {
    const DramAddress a = map(addr);
    Bank& bank = m_banks[size_t(a.channel) * m_config.banks + a.bank];
    const uint32_t bpc = m_config.bytes_per_cycle;
    const Cycle burst = (std::max<uint32_t>(bytes, 1) + bpc - 1) / bpc;
    // A full controller queue: the request enters when an entry frees (held to its last data).
    const Cycle arrival = time;
    BackfillSlots::Pick entry;
    if (!m_queues.empty()) {
        entry = m_queues[a.channel].earliest(time, Cycle(m_config.t_rcd) + m_config.t_cas + burst);
        time = entry.start;
    }
    Timing t;
    if (!m_frfcfs || !row_hit_first(bank, a, time, burst, write, &t)) {
        // The first idle gap at or after `time` long enough for this access, given the row the
        // access before it leaves open.
        uint32_t next = bank.upper_bound(time);
        OpenRow open{bank.base_row, bank.base_activated, bank.base_end};
        Cycle s = time;
        if (next > 0) {
            const Booking& prev = bank.at(next - 1);
            open = {prev.row, prev.activated, prev.end};
            s = std::max(s, prev.end);
        }
        Cycle end = 0, act = kNoActivate;
        t = plan(a, s, open, burst, write, &end, &act);
        for (; next < bank.size && end > bank.at(next).start; ++next) {
            const Booking& b = bank.at(next);
            s = std::max(t.start, b.end);
            open = {b.row, b.activated, b.end};
            t = plan(a, s, open, burst, write, &end, &act);
        }
        const Cycle activated = act != kNoActivate ? act : open.activated;
        bank.insert(next, Booking{t.start, end, m_close_page ? kClosed : a.row, activated});
        if (act != kNoActivate) record_activate(a.channel, a.group, act);
    }
    record_column(a.channel, a.group, write, burst, t.column);
    m_ras_wait += t.ras_wait;
    m_activate_wait += t.activate_wait;
    m_refresh_wait += t.refresh_wait;
    m_column_wait += t.column_wait;
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
    if (!m_queues.empty()) {
        m_queues[a.channel].book(entry.slot, arrival, time, t.done);
        t.queue_wait = time - arrival;
        m_queue_wait += t.queue_wait;
        m_queue_full += t.queue_wait > 0;
    }
    ++bank.counts[size_t(t.result)];
    ++m_totals[size_t(t.result)];
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
            {"ras_wait_cycles", m_ras_wait},
            {"activate_wait_cycles", m_activate_wait},
            {"refresh_wait_cycles", m_refresh_wait},
            {"column_wait_cycles", m_column_wait},
            {"queue_wait_cycles", m_queue_wait},
            {"queue_full_requests", m_queue_full},
            {"scheduler", kDramSchedulerChoices.name(m_config.scheduler)},
            {"row_hits_first", m_hits_first},
            {"moved_back_cycles", m_moved_back},
            {"bank_groups", m_config.bank_groups},
            {"group_interleave_bytes", m_config.group_interleave_bytes},
            {"by_bank", by_bank}};
}

}  // namespace rtsim
