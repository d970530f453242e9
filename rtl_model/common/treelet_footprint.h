#pragma once
// The lines of each treelet, for treelet prefetching (Chou, Nowicki & Aamodt, "Treelet Prefetching
// for Ray Tracing", MICRO 2023: when a ray reaches a treelet's root, the treelet is prefetched).
//
// Chou et al. lay each treelet out contiguously, so a prefetcher needs only its root address and
// size. rtsim's images keep their depth-first layouts (every structure's, unchanged) and the
// partition carries no addresses, so the table learns a treelet's lines from the reads its rays
// make there: a line joins the treelet's list the first time a ray in the treelet reads it, in
// that order (the treelet's root first). A prefetch of "the whole treelet" is then every line
// rays have read in it so far; lines no ray ever reads are never prefetched, so this is the
// contiguous-layout prefetcher without its never-used lines (docs/treelets.md, "Prefetching").
// Plain C++, shared by every unit (one table per machine).
#include <algorithm>
#include <cstdint>
#include <unordered_set>
#include <vector>

#include "rtl_model/common/interfaces.h"

namespace rtsim {

struct FootprintLine {
    uint64_t line = 0;  ///< line address >> line shift
    DataKind kind = DataKind::node;
};

class TreeletFootprints {
public:
    /// max_lines: lines handed out per treelet entry (0: all); into: the level they fill.
    TreeletFootprints(uint32_t treelets, uint32_t line_bytes, uint32_t max_lines, ServedBy into);

    /// Data of the structure (nodes, triangles, references, cells, instances) is learnt; the
    /// model's own records (rays, hits, stacks, ray-buffer overflow) belong to no treelet.
    static bool learns(DataKind kind);
    /// A ray in `treelet` reads [addr, addr + bytes).
    void learn(uint32_t treelet, uint64_t addr, uint32_t bytes, DataKind kind);
    /// The lines to prefetch on entering `treelet`: its first max_lines (all when 0).
    template <class F>
    void for_each_prefetch(uint32_t treelet, F&& f) const {
        const auto& lines = m_lines[treelet];
        const size_t n = m_max_lines ? std::min<size_t>(m_max_lines, lines.size()) : lines.size();
        for (size_t i = 0; i < n; ++i) f(lines[i]);
    }
    /// How many lines a prefetch on entering `treelet` now takes, and the i-th of them (the
    /// list only grows, so an index taken at entry stays valid).
    uint32_t prefetch_count(uint32_t treelet) const {
        const size_t n = m_lines[treelet].size();
        return uint32_t(m_max_lines ? std::min<size_t>(m_max_lines, n) : n);
    }
    const FootprintLine& line(uint32_t treelet, uint32_t i) const { return m_lines[treelet][i]; }
    uint32_t line_bytes() const { return 1u << m_line_shift; }
    uint32_t line_shift() const { return m_line_shift; }
    ServedBy into() const { return m_into; }
    /// Treelets with at least one line learnt, and lines learnt over all treelets.
    uint64_t treelets_learnt() const;
    uint64_t lines_learnt() const { return m_total; }

private:
    uint32_t m_line_shift;
    uint32_t m_max_lines;
    ServedBy m_into;
    uint64_t m_total = 0;
    std::vector<std::vector<FootprintLine>> m_lines;
    std::vector<std::unordered_set<uint64_t>> m_seen;
};

}  // namespace rtsim
