#include "rtl_model/common/backfill_slots.h"

#include <algorithm>
#include <limits>

namespace rtsim {

BackfillSlots::BackfillSlots(uint32_t slots) : m_booked(slots), m_last_end(slots, 0), m_free(slots, 0) {}

BackfillSlots::Pick BackfillSlots::earliest(Cycle time, Cycle expected) const {
    // In time order no booking starts after `time`: the slot free earliest.
    if (time >= m_latest_start) return {m_free.top(), std::max(time, m_free.top_time())};
    Pick best{0, std::numeric_limits<Cycle>::max()};
    for (uint32_t s = 0; s < m_booked.size(); ++s) {
        Cycle at = time;
        for (const Interval& i : m_booked[s]) {
            if (i.end <= at) continue;
            if (i.start >= at + expected) break;  // the gap before it is long enough
            at = i.end;
        }
        if (at < best.start) best = {s, at};
        if (at == time) break;  // cannot do better
    }
    return best;
}

void BackfillSlots::book(uint32_t slot, Cycle start, Cycle end) {
    std::vector<Interval>& v = m_booked[slot];
    const auto at = std::upper_bound(v.begin(), v.end(), start, [](Cycle t, const Interval& i) { return t < i.start; });
    v.insert(at, {start, end});
    if (v.size() > kKeep) v.erase(v.begin());
    if (end > m_last_end[slot]) {
        m_last_end[slot] = end;
        m_free.set(slot, end);
    }
    m_latest_start = std::max(m_latest_start, start);
}

}  // namespace rtsim
