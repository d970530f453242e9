#pragma once
// A traversal unit's treelet prefetcher (Chou, Nowicki & Aamodt, "Treelet Prefetching for Ray
// Tracing", MICRO 2023): when the unit starts a treelet's queue (a batch of rays enters the
// treelet), the treelet's lines are requested ahead of its rays, root first, into the L1 or the
// L2 (treelets.prefetch_into). The lines come from the machine's footprint table
// (common/treelet_footprint.h), which the unit's own steps teach. The engine sends one line per
// cycle in time order with the unit's reads; a line whose target has no free MSHR waits for one
// (demand misses keep priority). With treelet queues a MIMD unit runs one treelet at a time, so
// entering another drops the lines not yet sent (replace). Without queues, or with a SIMT
// unit's warps each in a treelet of its own, rays enter treelets interleaved: each entry joins
// the queue behind the others (append), a treelet entered among the last kRecent entries is not
// queued again, and past kMaxQueued lines the oldest unsent ones are dropped.
// Prefetching changes no traversal, hit or work count: only which lines are in the caches.
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "rtl_model/common/treelet_footprint.h"
#include "rtl_model/traversal/step_demand.h"

namespace rtsim {

class TreeletPrefetcher {
public:
    /// Entries remembered, in append mode, so a treelet rays keep re-entering (the root's) is
    /// queued once per kRecent entries of others.
    static constexpr size_t kRecent = 8;
    /// Lines waiting to be sent, at most, in append mode.
    static constexpr size_t kMaxQueued = 4096;

    /// table: the machine's footprint table, or null (prefetching off: every call is a no-op).
    /// replace: one treelet at a time (treelet queues on a MIMD unit); else append.
    void attach(TreeletFootprints* table, bool replace) {
        m_table = table;
        m_replace = replace;
    }
    bool on() const { return m_table != nullptr; }

    /// A step of a ray in `treelet` read its demand's lines: the table learns them.
    void learn(uint32_t treelet, const Fetch& f) {
        if (TreeletFootprints::learns(f.kind)) m_table->learn(treelet, f.addr, f.bytes, f.kind);
    }

    /// A ray of the unit entered `treelet` (took it from its queue, or stepped into it): a new
    /// treelet queues its lines.
    void enter(uint32_t treelet, Cycle t) {
        if (m_replace) {
            if (m_current == int64_t(treelet)) return;
            m_current = treelet;
            m_cancelled += m_queue.size() - m_head;
            m_queue.clear();
            m_head = 0;
        } else {
            if (std::find(m_recent.begin(), m_recent.end(), int64_t(treelet)) != m_recent.end()) return;
            m_recent[m_next_recent++ % kRecent] = treelet;
            if (m_head == m_queue.size() || m_head > kMaxQueued) {  // sent lines are forgotten
                m_queue.erase(m_queue.begin(), m_queue.begin() + std::ptrdiff_t(m_head));
                m_head = 0;
            }
        }
        if (m_head == m_queue.size()) m_last = t;
        const size_t before = m_queue.size();
        m_table->for_each_prefetch(treelet, [&](const FootprintLine& l) { m_queue.push_back(l); });
        m_queued += m_queue.size() - before;
        ++m_entries;
        if (!m_replace && m_queue.size() - m_head > kMaxQueued) {
            const size_t drop = m_queue.size() - m_head - kMaxQueued;
            m_cancelled += drop;
            m_head += drop;
        }
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
    bool m_replace = true;
    int64_t m_current = -1;
    std::array<int64_t, kRecent> m_recent = [] {
        std::array<int64_t, kRecent> a{};
        a.fill(-1);
        return a;
    }();
    size_t m_next_recent = 0;
    std::vector<FootprintLine> m_queue;
    size_t m_head = 0;
    Cycle m_last = 0, m_retry = 0;
    uint64_t m_entries = 0, m_queued = 0, m_sent = 0, m_cancelled = 0, m_waits = 0;
};

}  // namespace rtsim
