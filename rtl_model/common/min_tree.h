#pragma once
// The earliest of a fixed set of per-slot times (ray contexts' next events, MSHRs' free cycles):
// a tournament tree (Knuth, TAOCP vol. 3, 5.4.1 "replacement selection") over packed keys
// (time << kSlotBits | slot), so each inner node holds the smaller key of its two children and
// ties go to the lower slot by the key's order alone. Setting a slot's time updates its leaf and
// the log2(slots) nodes above it with one load, one min and one store each (no indirection
// through slot indices, no allocation); the earliest slot is the root. It replaced a binary heap
// of events and a linear scan of MSHRs, each a fifth of the model's time in profiles
// (docs/benchmarks.md, "Simulator speed").
#include <cstdint>
#include <limits>
#include <vector>

#include "rtl_model/common/interfaces.h"

namespace rtsim {

template <int SlotBits>
class BasicMinTree {
public:
    static constexpr int kSlotBits = SlotBits;
    static constexpr Cycle kNever = std::numeric_limits<Cycle>::max() >> kSlotBits;  ///< no time set
    static constexpr uint32_t kMaxSlots = 1u << kSlotBits;

    /// `slots` (<= kMaxSlots) slots, each at `initial` (kNever: empty).
    explicit BasicMinTree(uint32_t slots, Cycle initial = kNever) {
        m_leaves = 1;
        while (m_leaves < slots) m_leaves <<= 1;
        m_key.assign(2 * m_leaves, key(kNever, 0));
        for (uint32_t i = 0; i < m_leaves; ++i) m_key[m_leaves + i] = key(i < slots ? initial : kNever, i);
        for (uint32_t n = m_leaves - 1; n >= 1; --n) m_key[n] = min(m_key[2 * n], m_key[2 * n + 1]);
    }

    /// Slot s's time is now `time` (< kNever, or kNever to empty it).
    void set(uint32_t s, Cycle time) {
        uint64_t* keys = m_key.data();
        uint32_t n = m_leaves + s;
        uint64_t k = key(time, s);
        keys[n] = k;
        // The key coming up stays in a register: each level loads only the sibling and the old
        // parent, neither of which waits for the store below it (reloading both children made
        // every level wait for the previous level's store, the unit's longest dependency chain).
        for (; n > 1; n >>= 1) {
            k = min(k, keys[n ^ 1]);
            uint64_t& parent = keys[n >> 1];
            if (parent == k) break;  // nothing above changes
            parent = k;
        }
    }
    /// The earliest slot (lowest index among equal times) and its time.
    uint32_t top() const { return uint32_t(m_key[1] & (kMaxSlots - 1)); }
    Cycle top_time() const { return m_key[1] >> kSlotBits; }
    bool empty() const { return top_time() == kNever; }
    /// The slot that would be the earliest without the top one (kMaxSlots: none): the smallest
    /// of the subtrees beside the top's path, log2(slots) loads. A driver prefetches its data.
    uint32_t runner_up() const {
        uint64_t best = key(kNever, 0);
        for (uint32_t n = m_leaves + top(); n > 1; n >>= 1) best = min(best, m_key[n ^ 1]);
        return (best >> kSlotBits) == kNever ? kMaxSlots : uint32_t(best & (kMaxSlots - 1));
    }

private:
    static uint64_t key(Cycle time, uint32_t s) { return (time << kSlotBits) | s; }
    static uint64_t min(uint64_t a, uint64_t b) { return a < b ? a : b; }
    uint32_t m_leaves = 1;
    std::vector<uint64_t> m_key;  ///< nodes 1..2L-1: the smallest key below each; leaves from L
};

/// Up to 4,096 slots (the config's limits on ray contexts and MSHRs); times below 2^52.
using MinTree = BasicMinTree<12>;

}  // namespace rtsim
