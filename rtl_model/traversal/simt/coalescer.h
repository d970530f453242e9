#pragma once
// Memory coalescing of one SIMT warp step: the reads of all stepping lanes merged into one
// request per distinct line, as a GPU's load unit merges a warp's accesses to one cache line
// (the lanes that read the same node or triangles pay for one access). Requests go out in
// address order; each covers the bytes its lanes touched in the line.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "rtl_model/traversal/step_demand.h"

namespace rtsim {

class LineCoalescer {
public:
    explicit LineCoalescer(uint32_t line_bytes) : m_shift(0) {
        while ((1u << m_shift) < line_bytes) ++m_shift;
    }

    void clear() { m_parts.clear(); }
    /// One lane's read (a plan's fetch or a ray record).
    void add(uint64_t addr, uint32_t bytes, DataKind kind) {
        ++m_lane_requests;
        for_each_line(addr, bytes, m_shift, [&](uint64_t line, uint32_t in_line) {
            const uint32_t lo = uint32_t(std::max(addr, line << m_shift) - (line << m_shift));
            m_parts.push_back(Part{line, lo, lo + in_line, kind});
        });
    }
    /// Calls f(addr, bytes, kind) once per distinct line; returns the requests made.
    template <class F>
    uint32_t issue(F&& f) {
        std::sort(m_parts.begin(), m_parts.end(), [](const Part& a, const Part& b) { return a.line < b.line; });
        uint32_t n = 0;
        for (size_t i = 0; i < m_parts.size();) {
            Part merged = m_parts[i];
            for (++i; i < m_parts.size() && m_parts[i].line == merged.line; ++i) {
                merged.lo = std::min(merged.lo, m_parts[i].lo);
                merged.hi = std::max(merged.hi, m_parts[i].hi);
            }
            f((merged.line << m_shift) + merged.lo, merged.hi - merged.lo, merged.kind);
            ++n;
        }
        m_requests += n;
        m_parts.clear();
        return n;
    }
    /// Reads the lanes asked for, and requests made after coalescing, so far.
    uint64_t lane_requests() const { return m_lane_requests; }
    uint64_t requests() const { return m_requests; }

private:
    struct Part {
        uint64_t line;
        uint32_t lo, hi;  ///< bytes [lo, hi) of the line
        DataKind kind;
    };
    uint32_t m_shift;
    std::vector<Part> m_parts;
    uint64_t m_lane_requests = 0, m_requests = 0;
};

}  // namespace rtsim
