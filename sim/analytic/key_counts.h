#pragma once
// Counts per key for the analytic profiler's hot loop: one add per line read and per step, into a
// small table that stays in the host's L1, instead of a walk down an ordered map. The counts go
// into the profile's ordered maps once sampling ends; they are whole numbers, so the maps hold
// exactly what one add per event would have left there.
#include <cstdint>

#include "sim/analytic/probe_table.h"

namespace rtsim {

class KeyCounts {
public:
    /// One more of `key` (any key but ~0u, the empty slot's mark; histogram keys use 18 bits).
    void add(uint32_t key, uint64_t n = 1) {
        bool found;
        m_table.find_or_add(key, found) += n;
    }
    /// Calls f(key, count) for every key counted, then forgets them.
    template <class F>
    void drain(F&& f) {
        m_table.for_each(f);
        m_table.reset(kInitialSlots);
    }

private:
    static constexpr size_t kInitialSlots = 256;
    struct Hash {
        size_t operator()(uint32_t key) const { return size_t((key * 0x9E3779B1u) >> 8); }
    };
    ProbeTable<uint32_t, uint64_t, Hash> m_table{kInitialSlots};
};

}  // namespace rtsim
