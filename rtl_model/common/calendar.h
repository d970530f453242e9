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

class BandwidthCalendar {
public:
    /// capacity: units (bytes, accesses, issues) per window; window: cycles; horizon: windows
    /// remembered (rounded up to a power of two).
    BandwidthCalendar(uint64_t capacity_per_window, uint32_t window_cycles, uint32_t horizon_windows = 1u << 14);

    /// Reserves `amount` units (<= capacity) at or after `time`; returns the cycle service starts
    /// (within the window, in proportion to what the window already serves).
    Cycle reserve(Cycle time, uint64_t amount);

    uint64_t capacity_per_window() const { return m_capacity; }
    uint32_t window_cycles() const { return m_window; }
    uint64_t total_reserved() const { return m_total; }

private:
    struct Slot {
        uint64_t window = ~0ull;
        uint64_t used = 0;
    };
    uint64_t m_capacity;
    uint32_t m_window;
    uint64_t m_mask;
    std::vector<Slot> m_slots;
    uint64_t m_total = 0;
};

}  // namespace rtsim
