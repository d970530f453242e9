#include "rtl_model/common/calendar.h"

#include <algorithm>

#include "traces/common/error.h"

namespace rtsim {

const char* data_kind_name(DataKind kind) {
    switch (kind) {
        case DataKind::node: return "node";
        case DataKind::triangle: return "triangle";
        case DataKind::ray: return "ray";
        case DataKind::hit: return "hit";
        case DataKind::stack: return "stack";
        case DataKind::ray_buffer: return "ray_buffer";
    }
    return "unknown";
}

OccupancyCalendar::OccupancyCalendar(uint32_t slots, uint32_t window_cycles, uint32_t horizon)
    : m_capacity(uint64_t(slots) * window_cycles), m_window(window_cycles) {
    require(slots > 0 && window_cycles > 0, "OccupancyCalendar: slots and window must be positive");
    uint64_t size = 1;
    while (size < horizon) size <<= 1;
    m_mask = size - 1;
    m_slots.resize(size);
}

OccupancyCalendar::Slot& OccupancyCalendar::slot(uint64_t w) {
    Slot& s = m_slots[w & m_mask];
    if (s.window != w && (s.window == ~0ull || s.window < w)) {
        s.window = w;  // a stale window from the past: reuse it
        s.used = 0;
    }
    return s;
}

Cycle OccupancyCalendar::earliest(Cycle time, Cycle expected) {
    expected = std::max<Cycle>(expected, 1);
    for (Cycle start = time;;) {
        Cycle blocked = 0;  // first window that lacks room, if any
        for (uint64_t w = start / m_window; w * m_window < start + expected; ++w) {
            Slot& s = slot(w);
            if (s.window != w) continue;  // beyond the horizon: treat as free
            Cycle lo = std::max<Cycle>(start, w * m_window), hi = std::min<Cycle>(start + expected, (w + 1) * m_window);
            if (s.used + (hi - lo) > m_capacity) {
                blocked = (w + 1) * m_window;
                break;
            }
        }
        if (!blocked) return start;
        start = blocked;
    }
}

void OccupancyCalendar::occupy(Cycle start, Cycle end) {
    for (uint64_t w = start / m_window; w * m_window < end; ++w) {
        Slot& s = slot(w);
        if (s.window != w) continue;
        s.used += std::min<Cycle>(end, (w + 1) * m_window) - std::max<Cycle>(start, w * m_window);
    }
}

BandwidthCalendar::BandwidthCalendar(uint64_t capacity, uint32_t window_cycles, uint32_t horizon)
    : m_capacity(capacity), m_window(window_cycles) {
    require(capacity > 0 && window_cycles > 0, "BandwidthCalendar: capacity and window must be positive");
    uint64_t size = 1;
    while (size < horizon) size <<= 1;
    m_mask = size - 1;
    m_slots.resize(size);
}

Cycle BandwidthCalendar::reserve(Cycle time, uint64_t amount) {
    if (amount > m_capacity) amount = m_capacity;  // one request never needs more than a window
    m_total += amount;
    for (uint64_t w = time / m_window;; ++w) {
        Slot& s = m_slots[w & m_mask];
        if (s.window != w) {
            if (s.window != ~0ull && s.window > w) continue;  // slot holds a later window: treat as full
            s.window = w;
            s.used = 0;
        }
        if (s.used + amount > m_capacity) continue;
        // Start inside the window after what it already serves (fluid approximation).
        Cycle start = w * m_window + (s.used * m_window) / m_capacity;
        s.used += amount;
        return start > time ? start : time;
    }
}

SlotCalendar::SlotCalendar(uint64_t capacity, uint32_t slot_cycles, uint32_t horizon)
    : m_capacity(capacity), m_slot(slot_cycles) {
    require(capacity > 0 && slot_cycles > 0, "SlotCalendar: capacity and slot must be positive");
    uint64_t size = 1;
    while (size < horizon) size <<= 1;
    m_mask = size - 1;
    m_slots.resize(size);
}

Cycle SlotCalendar::reserve(Cycle time, uint64_t amount) {
    if (amount > m_capacity) amount = m_capacity;
    for (uint64_t w = time / m_slot;; ++w) {
        Slot& s = m_slots[w & m_mask];
        if (s.slot != w) {
            if (s.slot != ~0ull && s.slot > w) continue;  // ring entry holds a later slot: treat as full
            s.slot = w;
            s.used = 0;
        }
        if (s.used + amount > m_capacity) continue;
        s.used += amount;
        Cycle start = w * m_slot;
        return start > time ? start : time;
    }
}

}  // namespace rtsim
