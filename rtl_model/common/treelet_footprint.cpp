#include "rtl_model/common/treelet_footprint.h"

#include <algorithm>

namespace rtsim {

TreeletFootprints::TreeletFootprints(uint32_t treelets, uint32_t line_bytes, uint32_t max_lines, ServedBy into)
    : m_line_shift(0), m_max_lines(max_lines), m_into(into), m_lines(treelets), m_seen(treelets) {
    while ((1u << m_line_shift) < line_bytes) ++m_line_shift;
}

bool TreeletFootprints::learns(DataKind kind) {
    return kind != DataKind::ray && kind != DataKind::hit && kind != DataKind::stack && kind != DataKind::ray_buffer;
}

void TreeletFootprints::learn(uint32_t treelet, uint64_t addr, uint32_t bytes, DataKind kind) {
    const uint64_t last = (addr + std::max<uint32_t>(bytes, 1) - 1) >> m_line_shift;
    for (uint64_t line = addr >> m_line_shift; line <= last; ++line) {
        if (!m_seen[treelet].insert(line).second) continue;
        m_lines[treelet].push_back({line, kind});
        ++m_total;
    }
}

uint64_t TreeletFootprints::treelets_learnt() const {
    return uint64_t(std::count_if(m_lines.begin(), m_lines.end(), [](const auto& l) { return !l.empty(); }));
}

}  // namespace rtsim
