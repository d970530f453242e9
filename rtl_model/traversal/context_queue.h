#pragma once
// The traversal unit's event queue: when each ray context's next phase is ready, and which
// context goes next (the earliest; ties to the lower context index), over a MinTree
// (rtl_model/common/min_tree.h). There is at most one pending event per context.
//
// The unit handles the top context's event and usually gives the context its next event at
// once; begin_pop() therefore leaves the context's old event in the tree and finish_pop() empties
// it only when the handler did not reschedule the context, so a step costs one tree update.
// Nothing reads the queue's top between begin_pop() and finish_pop().
#include <cstdint>

#include "rtl_model/common/interfaces.h"
#include "rtl_model/common/min_tree.h"

namespace rtsim {

class ContextQueue {
public:
    static constexpr Cycle kNever = MinTree::kNever;

    explicit ContextQueue(uint32_t contexts) : m_tree(contexts) {}

    /// Context c's next event is at `time` (replacing any it had).
    void schedule(uint32_t c, Cycle time) {
        if (c == m_popped) m_rescheduled = true;
        m_tree.set(c, time);
    }
    bool empty() const { return m_tree.empty(); }
    /// The context that goes next and its time.
    uint32_t top() const { return m_tree.top(); }
    Cycle top_time() const { return m_tree.top_time(); }
    /// The context that goes after the top one unless the top's handler schedules it earlier
    /// (kNone: no other), so its data can be prefetched into the host's cache one event ahead.
    uint32_t runner_up() const {
        const uint32_t c = m_tree.runner_up();
        return c == MinTree::kMaxSlots ? kNone : c;
    }
    /// Takes the top context's event (see the header comment); returns the context.
    uint32_t begin_pop() {
        m_popped = m_tree.top();
        m_rescheduled = false;
        return m_popped;
    }
    void finish_pop() {
        if (!m_rescheduled) m_tree.set(m_popped, kNever);
        m_popped = kNone;
    }

    static constexpr uint32_t kNone = 0xFFFFFFFFu;

private:
    MinTree m_tree;
    uint32_t m_popped = kNone;
    bool m_rescheduled = false;
};

}  // namespace rtsim
