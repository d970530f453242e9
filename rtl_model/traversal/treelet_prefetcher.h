#pragma once
// A traversal unit's treelet prefetcher (Chou, Nowicki & Aamodt, "Treelet Prefetching for Ray
// Tracing", MICRO 2023): when the unit starts a treelet's queue (a batch of rays enters the
// treelet), the treelet's lines are requested ahead of its rays, root first, into the L1 or the
// L2 (treelets.prefetch_into). The lines come from the machine's footprint table
// (common/treelet_footprint.h), which the unit's own steps teach. The engine sends one line per
// cycle in time order with the unit's reads; a line whose target has no free MSHR waits for one
// (demand misses keep priority). Entering another treelet drops the lines not yet sent.
// Prefetching changes no traversal, hit or work count: only which lines are in the caches.
#include <algorithm>
#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "rtl_model/common/treelet_footprint.h"
#include "rtl_model/traversal/step_demand.h"

namespace rtsim {

class TreeletPrefetcher {
public:
    /// table: the machine's footprint table, or null (prefetching off: every call is a no-op).
    void attach(TreeletFootprints* table) { m_table = table; }
    bool on() const { return m_table != nullptr; }

    /// A step of a ray in `treelet` read its demand's lines: the table learns them.
    void learn(uint32_t treelet, const Fetch& f) {
        if (TreeletFootprints::learns(f.kind)) m_table->learn(treelet, f.addr, f.bytes, f.kind);
    }

    /// The unit took a ray of `treelet`: a new treelet queues its lines.
    void enter(uint32_t treelet, Cycle t) {
        if (m_current == int64_t(treelet)) return;
        m_current = treelet;
        m_cancelled += m_queue.size() - m_head;
        m_queue.clear();
        m_head = 0;
        m_table->for_each_prefetch(treelet, [&](const FootprintLine& l) { m_queue.push_back(l); });
        m_queued += m_queue.size();
        ++m_entries;
        m_last = t;
    }

    /// Sends queued lines up to cycle t, one per cycle since the last call.
    void drain(MemIf& mem, Cycle t) {
        if (m_head == m_queue.size() || t < m_retry) return;
        uint64_t budget = std::max<Cycle>(1, t - std::min(t, m_last));
        m_last = t;
        const uint32_t bytes = m_table->line_bytes();
        for (; budget && m_head < m_queue.size(); --budget) {
            const FootprintLine& l = m_queue[m_head];
            MemRequest req{l.line << m_table->line_shift(), bytes, false, l.kind, t, nullptr, true, m_table->into()};
            const Cycle retry = mem.access(req);
            if (retry > t) {  // no free MSHR at the target: try again when one frees
                m_retry = retry;
                ++m_waits;
                return;
            }
            ++m_head;
            ++m_sent;
        }
    }

    /// {entries, queued, sent, cancelled, waits} (unit stats `prefetch`).
    nlohmann::json stats_json() const {
        return {{"entries", m_entries}, {"queued", m_queued}, {"sent", m_sent}, {"cancelled", m_cancelled}, {"waits", m_waits}};
    }

private:
    TreeletFootprints* m_table = nullptr;
    int64_t m_current = -1;
    std::vector<FootprintLine> m_queue;
    size_t m_head = 0;
    Cycle m_last = 0, m_retry = 0;
    uint64_t m_entries = 0, m_queued = 0, m_sent = 0, m_cancelled = 0, m_waits = 0;
};

}  // namespace rtsim
