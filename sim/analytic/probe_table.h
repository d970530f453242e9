#pragma once
// The analytic profiler's hot-loop table: open addressing with linear probing, a power-of-two
// number of slots kept at most half full, a key beside its value so that a probe touches one host
// cache line. Its two uses differ in key, value, hash and allocator: the last use of every line
// (tens of MB on a large scene, probed at random, so on huge pages) and small per-key counts that
// stay in the host's L1.
#include <algorithm>
#include <cassert>
#include <cstddef>
#include <memory>
#include <vector>

namespace rtsim {

template <class Key, class Value, class Hash, template <class> class Alloc = std::allocator>
class ProbeTable {
public:
    static constexpr Key kEmpty = Key(~Key(0));  ///< the empty slot's mark; never a key

    explicit ProbeTable(size_t slots_pow2) { reset(slots_pow2); }

    /// `key`'s value; `found` says whether it was there (a new key starts at Value{}).
    Value& find_or_add(Key key, bool& found) {
        assert(key != kEmpty);
        if (2 * (m_size + 1) > m_slots.size()) grow();
        for (size_t i = slot_of(key);; i = (i + 1) & m_mask) {
            Slot& s = m_slots[i];
            found = s.key == key;
            if (found) return s.value;
            if (s.key == kEmpty) {
                s.key = key;
                ++m_size;
                return s.value;
            }
        }
    }
    /// Brings `key`'s first probe into the host's cache (speed only).
    void prefetch(Key key) const { __builtin_prefetch(&m_slots[slot_of(key)]); }
    /// Calls f(key, value) for every key held, in slot order.
    template <class F>
    void for_each(F&& f) const {
        for (const Slot& s : m_slots)
            if (s.key != kEmpty) f(s.key, s.value);
    }
    /// Forgets every key, keeping the slots.
    void clear() {
        std::fill(m_slots.begin(), m_slots.end(), Slot{});
        m_size = 0;
    }
    /// Forgets every key and starts again with `slots_pow2` slots.
    void reset(size_t slots_pow2) {
        assert(slots_pow2 >= 2 && (slots_pow2 & (slots_pow2 - 1)) == 0);
        m_slots.assign(slots_pow2, Slot{});
        m_mask = slots_pow2 - 1;
        m_size = 0;
    }
    size_t size() const { return m_size; }

private:
    struct Slot {
        Key key = kEmpty;
        Value value{};
    };
    size_t slot_of(Key key) const { return size_t(Hash{}(key)) & m_mask; }
    void grow() {
        std::vector<Slot, Alloc<Slot>> old(m_slots.size() * 2);
        old.swap(m_slots);
        m_mask = m_slots.size() - 1;
        for (const Slot& s : old) {
            if (s.key == kEmpty) continue;
            size_t i = slot_of(s.key);
            while (m_slots[i].key != kEmpty) i = (i + 1) & m_mask;
            m_slots[i] = s;
        }
    }

    std::vector<Slot, Alloc<Slot>> m_slots;
    size_t m_mask = 0;
    size_t m_size = 0;
};

}  // namespace rtsim
