#pragma once
// Counts per key for the analytic profiler's hot loop: one add per line read and per step, into a
// small open-addressing table that stays in the host's L1, instead of a walk down an ordered map.
// The counts go into the profile's ordered maps once sampling ends; they are whole numbers, so the
// maps hold exactly what one add per event would have left there.
#include <cassert>
#include <cstdint>
#include <vector>

namespace rtsim {

class KeyCounts {
public:
    KeyCounts() : m_slots(kInitialSlots) {}

    /// One more of `key` (any key but ~0u, the empty slot's mark).
    void add(uint32_t key) {
        assert(key != kEmpty);
        size_t i = slot_of(key);
        while (m_slots[i].key != key) {
            if (m_slots[i].key == kEmpty) {
                if (2 * (m_size + 1) > m_slots.size()) {
                    grow();
                    return add(key);
                }
                m_slots[i].key = key;
                ++m_size;
                break;
            }
            i = (i + 1) & (m_slots.size() - 1);
        }
        m_slots[i].count += 1;
    }
    /// Calls f(key, count) for every key counted, then forgets them.
    template <class F>
    void drain(F&& f) {
        for (Slot& s : m_slots)
            if (s.key != kEmpty) f(s.key, s.count);
        m_slots.assign(kInitialSlots, Slot{});
        m_size = 0;
    }

private:
    static constexpr uint32_t kEmpty = ~0u;  // histogram keys use 18 bits, test counts a few
    static constexpr size_t kInitialSlots = 256;
    struct Slot {
        uint32_t key = kEmpty;
        uint64_t count = 0;
    };
    size_t slot_of(uint32_t key) const { return size_t((key * 0x9E3779B1u) >> 8) & (m_slots.size() - 1); }
    void grow() {
        std::vector<Slot> old(m_slots.size() * 2);
        old.swap(m_slots);
        m_size = 0;
        for (const Slot& s : old)
            if (s.key != kEmpty) {
                size_t i = slot_of(s.key);
                while (m_slots[i].key != kEmpty) i = (i + 1) & (m_slots.size() - 1);
                m_slots[i] = s;
                ++m_size;
            }
    }

    std::vector<Slot> m_slots;
    size_t m_size = 0;
};

}  // namespace rtsim
