#include "rtl_model/mem/cache_sets.h"

#include <array>
#include <cstdlib>
#include <new>
#include <sstream>

#include "traces/common/error.h"

namespace rtsim {

namespace {
constexpr uint32_t kHostLine = 64;
}  // namespace

CacheSets::CacheSets(uint64_t sets, uint32_t ways, uint32_t line_shift)
    : m_ways(ways),
      m_stride((kTagsOffset + 6 * ways + kHostLine - 1) / kHostLine * kHostLine),
      m_tag_shift(0),
      m_set_mask(sets - 1),
      m_line_shift(line_shift) {
    while ((uint64_t(1) << m_tag_shift) < sets) ++m_tag_shift;
    const size_t bytes = size_t(sets) * m_stride;
    auto* p = static_cast<uint8_t*>(std::aligned_alloc(kHostLine, bytes));
    if (!p) throw std::bad_alloc();
    m_blocks.reset(p);
    std::memset(p, 0, bytes);  // latest fill 0, clock 0, stamps 0 (never used)
    for (uint64_t s = 0; s < sets; ++s) std::fill_n(tags_of(block(s)), ways, kInvalidTag);
}

void CacheSets::FreeAligned::operator()(uint8_t* p) const { std::free(p); }

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
