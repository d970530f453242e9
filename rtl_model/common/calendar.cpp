#include "rtl_model/common/calendar.h"

#include <algorithm>

#include "traces/common/error.h"

namespace rtsim {

WindowRing::WindowRing(uint32_t horizon) {
    uint64_t size = 1;
    while (size < horizon) size <<= 1;
    m_mask = size - 1;
    m_entries.resize(size);
}

BandwidthCalendar::BandwidthCalendar(uint64_t capacity, uint32_t window_cycles, uint32_t horizon)
    : m_capacity(capacity), m_window(window_cycles), m_window_of(window_cycles), m_per_unit(capacity), m_ring(horizon) {
    require(capacity > 0 && window_cycles > 0, "BandwidthCalendar: capacity and window must be positive");
}

Cycle BandwidthCalendar::reserve(Cycle time, uint64_t amount) {
    m_total += amount;
    // A request larger than a window (a 64-byte line on a 1 B/cycle channel) takes consecutive
    // windows' worth of capacity; clamping it to one window would let the resource exceed its peak.
    Cycle first = reserve_chunk(time, amount < m_capacity ? amount : m_capacity);
    Cycle at = first;
    for (uint64_t left = amount > m_capacity ? amount - m_capacity : 0; left > 0;) {
        uint64_t chunk = left < m_capacity ? left : m_capacity;
        at = reserve_chunk(at, chunk);
        left -= chunk;
    }
    return first;
}

Cycle BandwidthCalendar::reserve_chunk(Cycle time, uint64_t amount) {
    for (uint64_t w = m_window_of.div(time);; ++w) {
        uint64_t* used = m_ring.used(w);
        if (!used || *used + amount > m_capacity) continue;  // a later window in the entry: full
        // Start inside the window after what it already serves (fluid approximation).
        Cycle start = w * m_window + m_per_unit.div(*used * m_window);
        *used += amount;
        return start > time ? start : time;
    }
}

SlotCalendar::SlotCalendar(uint64_t capacity, uint32_t slot_cycles, uint32_t horizon)
    : m_capacity(capacity), m_slot(slot_cycles), m_slot_of(slot_cycles), m_ring(horizon) {
    require(capacity > 0 && slot_cycles > 0, "SlotCalendar: capacity and slot must be positive");
}

Cycle SlotCalendar::reserve(Cycle time, uint64_t amount) {
    if (amount > m_capacity) amount = m_capacity;
    for (uint64_t w = m_slot_of.div(time);; ++w) {
        uint64_t* used = m_ring.used(w);
        if (!used || *used + amount > m_capacity) continue;  // a later slot in the entry: full
        *used += amount;
        Cycle start = w * m_slot;
        return start > time ? start : time;
    }
}

}  // namespace rtsim
