#pragma once
// The traversal unit's event queue: when each ray context's next phase is ready, and which
// context goes next (the earliest; ties to the lower context index). A tournament tree over the
// contexts (Knuth, TAOCP vol. 3, 5.4.1 "replacement selection"): scheduling a context updates
// its leaf and the log2(contexts) winners above it; the next context is the root's winner. It
// replaces a binary heap of events (a fifth of the model's time in profiles, issue 15): there
// is at most one pending event per context, so a tree indexed by context needs no allocation
// and each operation is a few compares.
#include <cstdint>
#include <limits>
#include <vector>

#include "rtl_model/common/interfaces.h"

namespace rtsim {

class ContextQueue {
public:
    static constexpr Cycle kNever = std::numeric_limits<Cycle>::max();

    explicit ContextQueue(uint32_t contexts) {
        m_leaves = 1;
        while (m_leaves < contexts) m_leaves <<= 1;
        m_time.assign(m_leaves, kNever);
        m_winner.assign(2 * m_leaves, 0);
        for (uint32_t i = 0; i < m_leaves; ++i) m_winner[m_leaves + i] = i;
        for (uint32_t n = m_leaves - 1; n >= 1; --n) m_winner[n] = better(m_winner[2 * n], m_winner[2 * n + 1]);
    }

    /// Context c's next event is at `time` (replacing any it had).
    void schedule(uint32_t c, Cycle time) {
        m_time[c] = time;
        for (uint32_t n = (m_leaves + c) >> 1; n >= 1; n >>= 1) m_winner[n] = better(m_winner[2 * n], m_winner[2 * n + 1]);
    }
    bool empty() const { return m_time[m_winner[1]] == kNever; }
    /// The context that goes next and its time.
    uint32_t top() const { return m_winner[1]; }
    Cycle top_time() const { return m_time[m_winner[1]]; }
    /// Takes the top context's event without updating the tree yet: the caller usually gives the
    /// context its next event at once (schedule() then updates its path once, not twice) and
    /// calls finish_pop() after. Nodes left stale meanwhile all lie on the popped context's path,
    /// which schedule() or finish_pop() recomputes; top() is not read in between.
    uint32_t begin_pop() {
        m_popped = m_winner[1];
        m_time[m_popped] = kNever;
        return m_popped;
    }
    void finish_pop() {
        if (m_time[m_popped] == kNever) schedule(m_popped, kNever);
    }

private:
    uint32_t better(uint32_t a, uint32_t b) const {
        return m_time[b] < m_time[a] || (m_time[b] == m_time[a] && b < a) ? b : a;
    }
    uint32_t m_leaves = 1;
    uint32_t m_popped = 0;
    std::vector<Cycle> m_time;        ///< per context (padded to a power of two): next event, or kNever
    std::vector<uint32_t> m_winner;   ///< tree nodes 1..2L-1: the earliest context below each
};

}  // namespace rtsim
