#pragma once
// A traversal unit's treelet prefetcher (Chou, Nowicki & Aamodt, "Treelet Prefetching for Ray
// Tracing", MICRO 2023): when rays enter a treelet, the treelet's lines are requested ahead of
// them, root first, into the L1 or the L2 (treelets.prefetch_into). The lines come from the
// machine's footprint table (common/treelet_footprint.h), which the unit's own steps teach.
//
// The prefetcher keeps one stream per consumer of the unit, each holding the lines of the
// treelet its rays are in: with treelet queues a MIMD unit is one consumer and a SIMT unit's
// warps are one each; without queues every ray context (MIMD) or lane (SIMT) is one. A stream
// entering another treelet drops its unsent lines (cancelled), so what is sent is always for a
// treelet some rays are in now. Without queues a ray's stream re-entering one of its last
// kRecent treelets (the ray back in its parent's) queues nothing, since those lines were just
// sent; a queue's consumer picking a treelet again prefetches it again (its lines may be gone). The engine sends one
// line per cycle, round robin over the streams with lines, in time order with the unit's reads;
// a line whose target has no free MSHR waits for one (demand misses keep priority).
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
    /// Treelets a stream remembers having entered: re-entering one queues nothing.
    static constexpr size_t kRecent = 4;

    /// table: the machine's footprint table, or null (prefetching off: every call is a no-op);
    /// streams: the unit's consumers (above); per_ray: a stream per ray (no treelet queues).
    void attach(TreeletFootprints* table, uint32_t streams, bool per_ray) {
        m_table = table;
        m_streams.assign(std::max<uint32_t>(1, streams), Stream{});
        m_per_ray = per_ray;
    }
    bool on() const { return m_table != nullptr; }

    /// A step of a ray in `treelet` read its demand's lines: the table learns them.
    void learn(uint32_t treelet, const Fetch& f) {
        if (TreeletFootprints::learns(f.kind)) m_table->learn(treelet, f.addr, f.bytes, f.kind);
    }

    /// The rays of `stream` entered `treelet` (took it from its queue, or stepped into it).
    void enter(uint32_t stream, uint32_t treelet, Cycle t) {
        Stream& s = m_streams[stream];
        if (s.treelet == int64_t(treelet)) return;
        const uint32_t unsent = s.end - s.next;
        m_cancelled += unsent;
        m_pending -= unsent;
        s.treelet = treelet;
        s.next = s.end = 0;
        if (m_per_ray) {
            if (std::find(s.recent.begin(), s.recent.end(), int64_t(treelet)) != s.recent.end()) return;
            s.recent[s.next_recent++ % kRecent] = treelet;
        }
        if (m_pending == 0) m_last = t;  // the engine was idle: its budget starts now
        s.end = m_table->prefetch_count(treelet);
        m_queued += s.end;
        m_pending += s.end;
        ++m_entries;
    }

    /// Sends queued lines up to cycle t, one per cycle since the last call.
    void drain(MemIf& mem, Cycle t) {
        if (m_pending == 0 || t < m_retry) return;
        uint64_t budget = std::max<Cycle>(1, t - std::min(t, m_last));
        m_last = t;
        const uint32_t bytes = m_table->line_bytes();
        while (budget && m_pending) {
            Stream& s = m_streams[m_turn];
            if (s.next == s.end) {
                m_turn = (m_turn + 1) % m_streams.size();
                continue;
            }
            const FootprintLine& l = m_table->line(uint32_t(s.treelet), s.next);
            MemRequest req{l.line << m_table->line_shift(), bytes, false, l.kind, t, nullptr, true, m_table->into()};
            const Cycle retry = mem.access(req);
            if (retry > t) {  // no free MSHR at the target: try again when one frees
                m_retry = retry;
                ++m_waits;
                return;
            }
            ++s.next;
            --m_pending;
            ++m_sent;
            --budget;
            m_turn = (m_turn + 1) % m_streams.size();
        }
    }

    /// {entries, queued, sent, cancelled, waits} (unit stats `prefetch`).
    nlohmann::json stats_json() const {
        return {{"entries", m_entries}, {"queued", m_queued}, {"sent", m_sent}, {"cancelled", m_cancelled}, {"waits", m_waits}};
    }

private:
    struct Stream {
        int64_t treelet = -1;
        uint32_t next = 0, end = 0;  ///< the treelet's footprint lines [next, end) are unsent
        std::array<int64_t, kRecent> recent = [] {
            std::array<int64_t, kRecent> a{};
            a.fill(-1);
            return a;
        }();
        size_t next_recent = 0;
    };
    TreeletFootprints* m_table = nullptr;
    std::vector<Stream> m_streams{1};
    bool m_per_ray = false;
    size_t m_turn = 0;
    uint64_t m_pending = 0;
    Cycle m_last = 0, m_retry = 0;
    uint64_t m_entries = 0, m_queued = 0, m_sent = 0, m_cancelled = 0, m_waits = 0;
};

}  // namespace rtsim
