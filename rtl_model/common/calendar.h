#pragma once
// Reservation of shared resources by units that run ahead of each other within a quantum.
//
// InOrderResource: one issuer, requests in time order; exact.
// BandwidthCalendar: capacity per window of cycles, requests in any time order; a request takes
// the first window at or after its time that has room, so a saturated resource pushes requests
// later (queueing) and sustains exactly its capacity, while early-arriving requests are not
// blocked by later ones (a plain next-free-cycle counter would serialise them behind the future).
#include <cstdint>
#include <vector>

#include "rtl_model/common/divider.h"
#include "rtl_model/common/interfaces.h"

namespace rtsim {

class InOrderResource {
public:
    /// Occupies the resource for `busy` cycles from max(time, free); returns the start cycle.
    Cycle reserve(Cycle time, Cycle busy) {
        Cycle start = time > m_free ? time : m_free;
        m_free = start + busy;
        m_busy += busy;
        return start;
    }
    Cycle busy_cycles() const { return m_busy; }
    Cycle free_at() const { return m_free; }

private:
    Cycle m_free = 0;
    Cycle m_busy = 0;
};

/// Usage per window of cycles over a sliding horizon: a ring indexed by window number, shared by
/// the calendars below. An entry still holding an older window is reused (reset to zero).
class WindowRing {
public:
    explicit WindowRing(uint32_t horizon_windows);
    /// Usage counter of window w, or nullptr when its entry holds a later window (w lies more
    /// than a horizon behind the newest request; each calendar decides what that means).
    uint64_t* used(uint64_t w) {
        Entry& e = m_entries[w & m_mask];
        if (e.window == w) return &e.used;
        if (e.window != ~0ull && e.window > w) return nullptr;
        e.window = w;  // empty or an older window: reuse the entry
        e.used = 0;
        return &e.used;
    }

private:
    struct Entry {
        uint64_t window = ~0ull;
        uint64_t used = 0;
    };
    uint64_t m_mask;
    std::vector<Entry> m_entries;
};

class BandwidthCalendar {
public:
    /// capacity: units (bytes, accesses, issues) per window; window: cycles; horizon: windows
    /// remembered (rounded up to a power of two).
    BandwidthCalendar(uint64_t capacity_per_window, uint32_t window_cycles, uint32_t horizon_windows = 1u << 14);

    /// Reserves `amount` units at or after `time`; returns the cycle service starts (within the
    /// window, in proportion to what the window already serves). More than a window's capacity
    /// spills into the following windows.
    Cycle reserve(Cycle time, uint64_t amount);

    uint64_t capacity_per_window() const { return m_capacity; }
    uint32_t window_cycles() const { return m_window; }
    uint64_t total_reserved() const { return m_total; }

private:
    Cycle reserve_chunk(Cycle time, uint64_t amount);  ///< amount <= capacity

    uint64_t m_capacity;
    uint32_t m_window;
    Divider m_window_of;   ///< cycle -> window
    Divider m_per_unit;    ///< (units x window cycles) -> cycles into the window
    WindowRing m_ring;
    uint64_t m_total = 0;
};

/// Exact slot reservation for the detailed level: `capacity` units per slot of `slot_cycles`
/// cycles (one bank access, `shared_count` pipeline issues, a channel's bytes per cycle). A request
/// takes the first slot at or after its time with room and starts at max(time, slot start), so
/// requests contend cycle by cycle in the order they arrive (at equal cycles: arrival order, i.e.
/// fixed priority by SystemC process order). No fluid averaging: with units synchronised every
/// cycle (quantum 1) arrivals are in time order and this is a per-cycle arbiter.
class SlotCalendar {
public:
    SlotCalendar(uint64_t capacity_per_slot, uint32_t slot_cycles, uint32_t horizon_slots = 1u << 14);

    /// Reserves `amount` units (<= capacity) in one slot at or after `time`; returns the start cycle.
    Cycle reserve(Cycle time, uint64_t amount = 1);
    uint32_t slot_cycles() const { return m_slot; }

private:
    uint64_t m_capacity;
    uint32_t m_slot;
    Divider m_slot_of;  ///< cycle -> slot
    WindowRing m_ring;
};

}  // namespace rtsim
