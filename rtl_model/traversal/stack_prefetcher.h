#pragma once
// Stack-driven prefetching, traversal.stack_prefetch (TTP, the Tree Traversal Prefetcher: Tozlu,
// Naithani & Zhou, "TTP: A Hardware-Efficient Design for Precise Prefetching in Ray Tracing",
// arXiv 2605.16253, 2026). A depth-first walk that pops its stack twice in a row is going back
// up the tree, and the nodes it visits next are the ones whose addresses its hardware stack
// already holds: on such a pop the prefetcher requests the lines of the top `stack_prefetch`
// entries (the next to be popped, top first) into the unit's L1. No address is predicted, so
// nearly every prefetched line is read (the paper reports 98.92% L1 accuracy; an entry a pop
// skips, entered beyond the ray's best hit, is prefetched and never read).
//
// The paper's RT unit pops every node it visits (its children hit are pushed, the nearest popped
// next); ours visits the nearest child directly and pushes the others, so its pop is the paper's
// second pop in a row: a step that pushed nothing (a leaf, or a node none of whose children were
// hit) and shrank the stack. That is the trigger. A step's pop is known once its operations have
// run, so the requests are issued in the step's operations phase, in time order with the unit's
// reads. A line whose L1 has no free MSHR is dropped (demand misses keep priority; counted as
// `dropped`). One stream per ray context (MIMD), lane (SIMT) or packet (its shared stack).
// Assumed beyond the paper's description: at most kMaxLinesPerEntry lines per entry, and the
// unit keeps the last kRecent lines it sent so an entry still on a stack is not requested again
// at the next pop.
// Prefetching changes no traversal, hit or work count: only which lines are in the L1.
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "rtl_model/common/interfaces.h"
#include "rtl_model/traversal/step_demand.h"

namespace rtsim {

class StackPrefetcher {
public:
    static constexpr uint32_t kMaxEntries = 8;
    static constexpr uint32_t kMaxLinesPerEntry = 4;
    static constexpr size_t kRecent = 16;

    /// entries: stack entries prefetched per trigger (0: off); streams: the unit's contexts or lanes.
    void configure(uint32_t entries, uint32_t streams, uint32_t line_bytes) {
        m_entries = std::min(entries, kMaxEntries);
        m_streams.assign(m_entries ? streams : 0, Stream{});
        m_line_shift = 0;
        while ((1u << m_line_shift) < line_bytes) ++m_line_shift;
    }
    bool on() const { return m_entries != 0; }

    /// A new ray on stream s: nothing to prefetch yet.
    void begin(uint32_t s) {
        if (on()) m_streams[s].count = 0;
    }

    /// Stream s's stepper ran a step whose stack held `before` entries: a pop (the stack shrank)
    /// arms the stream with the reads of its stack's top entries; issue() requests them.
    void after_step(uint32_t s, const Stepper& stepper, int before) {
        if (!on()) return;
        Stream& st = m_streams[s];
        st.count = stepper.stack_size() < before && !stepper.done() ? stepper.stack_reads(st.reads, m_entries) : 0;
    }
    /// Arms stream s with `n` reads a recorded walk kept for its step (cooperation.h).
    void arm(uint32_t s, const Fetch* reads, uint32_t n) {
        if (!on()) return;
        Stream& st = m_streams[s];
        st.count = std::min(n, m_entries);
        std::copy(reads, reads + st.count, st.reads);
    }

    /// Stream s's operations phase at cycle t: requests the armed stream's lines.
    void issue(uint32_t s, MemIf& l1, Cycle t) {
        if (!on() || m_streams[s].count == 0) return;
        Stream& st = m_streams[s];
        ++m_triggers;
        for (uint32_t i = 0; i < st.count; ++i) {
            uint32_t lines = 0;
            for_each_line(st.reads[i].addr, st.reads[i].bytes, m_line_shift, [&](uint64_t line, uint32_t) {
                if (lines++ >= kMaxLinesPerEntry) return;
                if (std::find(m_recent.begin(), m_recent.end(), line) != m_recent.end()) {
                    ++m_repeats;
                    return;
                }
                m_recent[m_next_recent++ % kRecent] = line;
                const MemRequest req{line << m_line_shift, 1u << m_line_shift, false, st.reads[i].kind, t, nullptr, true,
                                     ServedBy::l1};
                if (l1.access(req) > t) ++m_dropped;  // no free MSHR: demand misses keep priority
                else ++m_sent;
            });
        }
        st.count = 0;
    }

    /// {triggers, sent, dropped, repeats} (unit stats `stack_prefetch`).
    nlohmann::json stats_json() const {
        return {{"triggers", m_triggers}, {"sent", m_sent}, {"dropped", m_dropped}, {"repeats", m_repeats}};
    }

private:
    struct Stream {
        uint32_t count = 0;         ///< armed: its ray's step popped; these reads go out in its operations phase
        Fetch reads[kMaxEntries];  ///< the stack's top entries' reads, next popped first
    };
    uint32_t m_entries = 0;
    uint32_t m_line_shift = 6;
    std::vector<Stream> m_streams;
    std::array<uint64_t, kRecent> m_recent = [] {  ///< the unit's last lines sent
        std::array<uint64_t, kRecent> a{};
        a.fill(~uint64_t(0));
        return a;
    }();
    size_t m_next_recent = 0;
    uint64_t m_triggers = 0, m_sent = 0, m_dropped = 0, m_repeats = 0;
};

}  // namespace rtsim
