#include "rtl_model/mem/cache_sets.h"

#include <array>
#include <sstream>

#include "traces/common/error.h"

namespace rtsim {

CacheSets::CacheSets(uint64_t sets, uint32_t ways, uint32_t line_shift)
    : m_ways(ways),
      m_stride(uint32_t((kTagsOffset + 6 * ways + AlignedBytes::kAlign - 1) / AlignedBytes::kAlign * AlignedBytes::kAlign)),
      m_tag_shift(0),
      m_set_mask(sets - 1),
      m_line_shift(line_shift) {
    while ((uint64_t(1) << m_tag_shift) < sets) ++m_tag_shift;
    m_blocks.resize(size_t(sets) * m_stride);  // zero: latest fill 0, clock 0, stamps 0 (never used)
    for (uint64_t s = 0; s < sets; ++s) std::fill_n(tags_of(block(s)), ways, kInvalidTag);
}

void CacheSets::beyond_tags(uint64_t line) const {
    std::ostringstream msg;
    msg << "model: address 0x" << std::hex << (line << m_line_shift) << std::dec
        << " is beyond what the cache model's tags cover (" << (32 + m_tag_shift + m_line_shift)
        << " address bits)";
    throw Error(msg.str());
}

uint16_t CacheSets::renumber(uint8_t* b) {
    uint16_t* stamps = stamps_of(b);
    // Ways by stamp; used ways (stamp > 0) get 1..n in the same order, never-used ways keep 0.
    std::array<uint32_t, 64> order{};
    for (uint32_t w = 0; w < m_ways; ++w) order[w] = w;
    std::sort(order.begin(), order.begin() + m_ways,
              [&](uint32_t a, uint32_t c) { return stamps[a] < stamps[c]; });
    uint16_t n = 0;
    for (uint32_t i = 0; i < m_ways; ++i)
        if (stamps[order[i]] != 0) stamps[order[i]] = ++n;
    return n;
}

}  // namespace rtsim
