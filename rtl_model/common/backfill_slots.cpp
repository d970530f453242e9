#include "rtl_model/common/backfill_slots.h"

#include <algorithm>
#include <limits>

namespace rtsim {

BackfillSlots::BackfillSlots(uint32_t slots) : m_booked(slots), m_last_end(slots, 0), m_free(slots, 0) {}

BackfillSlots::Pick BackfillSlots::earliest(Cycle time, Cycle expected) const {
    // In time order no booking starts after `time`: the slot free earliest.
    if (time >= m_latest_start) return {m_free.top(), std::max(time, m_free.top_time())};
    // A slot whose every booking has ended by `time` is free from then on.
    if (m_free.top_time() <= time) return {m_free.top(), time};
    Pick best{0, std::numeric_limits<Cycle>::max()};
    for (uint32_t s = 0; s < m_booked.size(); ++s) {
        const std::vector<Interval>& v = m_booked[s].v;
        // Intervals starting before time - m_longest have ended by `time`: skip them.
        const Cycle from = time > m_longest ? time - m_longest : 0;
        auto i = std::lower_bound(v.begin() + std::ptrdiff_t(m_booked[s].head), v.end(), from,
                                  [](const Interval& a, Cycle t) { return a.start < t; });
        Cycle at = std::max(time, m_booked[s].floor);
        for (; i != v.end(); ++i) {
            if (i->end <= at) continue;
            if (i->start >= at + expected) break;  // the gap before it is long enough
            at = i->end;
        }
        if (at < best.start) best = {s, at};
        if (at == time) break;  // cannot do better
    }
    return best;
}

void BackfillSlots::book(uint32_t slot, Cycle time, Cycle start, Cycle end) {
    Booked& b = m_booked[slot];
    std::vector<Interval>& v = b.v;
    // Most bookings start after every other: append; else insert in order.
    if (v.size() == b.head || v.back().start <= start) {
        v.push_back({start, end});
    } else {
        const auto at = std::upper_bound(v.begin() + std::ptrdiff_t(b.head), v.end(), start,
                                         [](Cycle t, const Interval& i) { return t < i.start; });
        v.insert(at, {start, end});
    }
    m_longest = std::max(m_longest, end - start);
    m_latest_start = std::max(m_latest_start, start);
    m_latest_request = std::max(m_latest_request, time);
    // Drop what no request can reach any more (ended a horizon before the latest stamp).
    for (; b.head < v.size() && v[b.head].end + kHorizon < m_latest_request; ++b.head)
        b.floor = std::max(b.floor, v[b.head].end);
    if (b.head > 64 && 2 * b.head > v.size()) {
        v.erase(v.begin(), v.begin() + std::ptrdiff_t(b.head));
        b.head = 0;
    }
    if (end > m_last_end[slot]) {
        m_last_end[slot] = end;
        m_free.set(slot, end);
    }
}

}  // namespace rtsim
