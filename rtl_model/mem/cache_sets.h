#pragma once
// The tags and LRU state of a set-associative cache model, packed set by set for the host.
//
// The simulator's time at the approx level goes largely to host cache misses in these arrays
// (the shared L2 model is 1,024 sets x 16 ways: kept as 64-bit tags, 64-bit LRU stamps and fill
// records in separate arrays it took 512 KiB and four host lines per lookup). Here a set is one
// block of whole host cache lines holding, in order:
//
//   latest fill (u64) | use clock (u16) | pad | tags (u32 x ways) | LRU stamps (u16 x ways)
//
// so a 16-way set is 128 bytes (two host lines) and a 4-way set 64 bytes (one); a lookup and its
// LRU update touch only its set's block. A tag is the line number without its set-index bits
// (the set implies them), which covers 2^32 x sets x line_bytes bytes of address space (the memory
// map's regions lie within a few tens of GiB); a line beyond that is an error, not a wrong hit.
// LRU stamps count uses per set (the order within a set is all replacement compares): a set's
// clock that would overflow 16 bits renumbers its stamps 1..n in the same order, so the victim is
// always the one a global use counter would choose (never-used ways first, the lowest way among
// equals). The latest fill cycle of a set lets a hit skip the per-line fill records (kept apart by
// the cache, touched on misses) when no line of the set can still be in flight.
#include <algorithm>
#include <cstdint>
#include <cstring>

#include "traces/accel/aligned_bytes.h"

namespace rtsim {

class CacheSets {
public:
    static constexpr uint32_t kNoWay = ~0u;

    /// `sets` must be a power of two (the caller's set mask).
    CacheSets(uint64_t sets, uint32_t ways, uint32_t line_shift);

    uint32_t ways() const { return m_ways; }
    uint64_t sets() const { return m_set_mask + 1; }
    uint64_t set_of(uint64_t line) const { return line & m_set_mask; }

    /// The way holding `line` in its set, or kNoWay.
    uint32_t find(uint64_t line) const {
        const uint32_t tag = tag_of(line);
        const uint32_t* tags = tags_of(block(set_of(line)));
        for (uint32_t w = 0; w < m_ways; ++w)
            if (tags[w] == tag) return w;
        return kNoWay;
    }
    /// Way `way` of `set` becomes the most recently used.
    void touch(uint64_t set, uint32_t way) {
        uint8_t* b = block(set);
        uint16_t clock;
        std::memcpy(&clock, b + kClockOffset, sizeof clock);
        if (clock == UINT16_MAX) clock = renumber(b);
        ++clock;
        std::memcpy(b + kClockOffset, &clock, sizeof clock);
        stamps_of(b)[way] = clock;
    }
    /// The least recently used way of `set` (never-used ways first, the lowest among equals).
    uint32_t victim(uint64_t set) const {
        const uint16_t* stamps = stamps_of(block(set));
        uint32_t v = 0;
        for (uint32_t w = 1; w < m_ways; ++w)
            if (stamps[w] < stamps[v]) v = w;
        return v;
    }
    bool valid(uint64_t set, uint32_t way) const { return tags_of(block(set))[way] != kInvalidTag; }
    /// Puts `line` (of this set) in way `way`, most recently used.
    void place(uint32_t way, uint64_t line) {
        const uint64_t set = set_of(line);
        tags_of(block(set))[way] = tag_of(line);
        touch(set, way);
    }
    /// No line of `set` is filled after this cycle (a bound: the latest fill ever placed).
    uint64_t latest_fill(uint64_t set) const {
        uint64_t c;
        std::memcpy(&c, block(set), sizeof c);
        return c;
    }
    void note_fill(uint64_t set, uint64_t ready) {
        if (ready > latest_fill(set)) std::memcpy(block(set), &ready, sizeof ready);
    }
    /// Brings the set's block into the host's cache ahead of a lookup (its first and last host
    /// lines: the whole block up to 16 ways, the tags and stamps of the first 8 ways beyond).
    void prefetch(uint64_t set) const {
        const uint8_t* b = block(set);
        __builtin_prefetch(b);
        __builtin_prefetch(b + m_stride - 64);
    }

private:
    static constexpr uint32_t kInvalidTag = ~0u;
    static constexpr uint32_t kClockOffset = 8;
    static constexpr uint32_t kTagsOffset = 16;

    uint32_t tag_of(uint64_t line) const {
        const uint64_t tag = line >> m_tag_shift;
        if (__builtin_expect(tag >= kInvalidTag, 0)) beyond_tags(line);
        return uint32_t(tag);
    }
    [[noreturn]] void beyond_tags(uint64_t line) const;
    uint8_t* block(uint64_t set) { return m_blocks.data() + set * m_stride; }
    const uint8_t* block(uint64_t set) const { return m_blocks.data() + set * m_stride; }
    static uint32_t* tags_of(uint8_t* b) { return reinterpret_cast<uint32_t*>(b + kTagsOffset); }
    static const uint32_t* tags_of(const uint8_t* b) {
        return reinterpret_cast<const uint32_t*>(b + kTagsOffset);
    }
    uint16_t* stamps_of(uint8_t* b) const {
        return reinterpret_cast<uint16_t*>(b + kTagsOffset + 4 * m_ways);
    }
    const uint16_t* stamps_of(const uint8_t* b) const {
        return reinterpret_cast<const uint16_t*>(b + kTagsOffset + 4 * m_ways);
    }
    /// Renumbers the used ways' stamps 1..n in the same order; returns n (the set's new clock).
    uint16_t renumber(uint8_t* b);

    uint32_t m_ways;
    uint32_t m_stride;     ///< bytes per set: a multiple of the host's 64-byte line
    uint32_t m_tag_shift;  ///< line-number bits the set index takes
    uint64_t m_set_mask;
    uint32_t m_line_shift;
    AlignedBytes m_blocks;  ///< the sets, 64-byte aligned
};

}  // namespace rtsim
