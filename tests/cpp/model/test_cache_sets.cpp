// The packed sets (cache_sets.h) against the plain LRU they replace: per line, a 64-bit tag and
// a stamp from one global use counter, the victim the least recently used way (never-used ways
// first, the lowest way among equals). Same hits, same victims, also after a set's 16-bit clock
// has been renumbered many times; a line beyond the tags' range is an error.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "rtl_model/mem/cache_sets.h"
#include "traces/common/error.h"

namespace rtsim {
namespace {

/// The reference: what the cache model kept before its sets were packed.
struct PlainLru {
    PlainLru(uint64_t sets, uint32_t ways)
        : ways(ways), mask(sets - 1), tags(sets * ways, ~0ull), last(sets * ways, 0) {}
    /// Returns the way hit, or the victim's way (set in *evicted whether it held a line) on a miss.
    uint32_t access(uint64_t line, bool* hit, bool* evicted) {
        const size_t set = size_t(line & mask) * ways;
        for (uint32_t w = 0; w < ways; ++w)
            if (tags[set + w] == line) {
                last[set + w] = ++clock;
                *hit = true;
                return w;
            }
        size_t v = set;
        for (size_t w = set + 1; w < set + ways; ++w)
            if (last[w] < last[v]) v = w;
        *hit = false;
        *evicted = tags[v] != ~0ull;
        tags[v] = line;
        last[v] = ++clock;
        return uint32_t(v - set);
    }
    uint32_t ways;
    uint64_t mask, clock = 0;
    std::vector<uint64_t> tags, last;
};

/// Drives both with `accesses` lines drawn from `distinct` lines (a few sets' worth reuse them).
void expect_same_as_plain(uint64_t sets, uint32_t ways, uint64_t distinct, uint64_t accesses, uint64_t base) {
    PlainLru plain(sets, ways);
    CacheSets packed(sets, ways, 6);
    std::mt19937_64 rng(sets * 131 + ways);
    std::uniform_int_distribution<uint64_t> pick(0, distinct - 1);
    uint64_t hits = 0;
    for (uint64_t i = 0; i < accesses; ++i) {
        const uint64_t line = base + pick(rng);
        bool hit = false, evicted = false;
        const uint32_t way = plain.access(line, &hit, &evicted);
        const uint64_t set = packed.set_of(line);
        const uint32_t found = packed.find(line);
        if (hit) {
            ASSERT_EQ(found, way) << "access " << i;
            packed.touch(set, found);
            ++hits;
            continue;
        }
        ASSERT_EQ(found, CacheSets::kNoWay) << "access " << i;
        const uint32_t victim = packed.victim(set);
        ASSERT_EQ(victim, way) << "access " << i;
        ASSERT_EQ(packed.valid(set, victim), evicted) << "access " << i;
        packed.place(victim, line);
    }
    EXPECT_GT(hits, 0u);
    EXPECT_LT(hits, accesses);
}

TEST(CacheSets, SameHitsAndVictimsAsAGlobalClockLru) {
    expect_same_as_plain(64, 4, 400, 200000, 0);                // the default L1's geometry
    expect_same_as_plain(1024, 16, 24000, 300000, 1ull << 26);  // the default L2's, at 4 GiB up
    expect_same_as_plain(4, 3, 20, 50000, 7);                   // odd ways, few sets
    expect_same_as_plain(1, 64, 90, 50000, 0);                  // fully associative, widest
}

TEST(CacheSets, RenumberedClocksKeepTheOrder) {
    // One set hit 2^16 times and more: its clock is renumbered, over and over, and the victims
    // still follow the global-clock LRU (and the never-used way stays first).
    expect_same_as_plain(1, 4, 3, 400000, 0);
    expect_same_as_plain(2, 8, 20, 600000, 0);
}

TEST(CacheSets, LatestFillBoundsTheSet) {
    CacheSets s(4, 2, 6);
    EXPECT_EQ(s.latest_fill(1), 0u);
    s.note_fill(1, 500);
    s.note_fill(1, 300);  // an earlier fill does not lower the bound
    EXPECT_EQ(s.latest_fill(1), 500u);
    EXPECT_EQ(s.latest_fill(0), 0u);
}

TEST(CacheSets, LineBeyondTheTagsIsAnError) {
    CacheSets s(1024, 16, 6);  // a tag is a line number without its 10 set bits, 32 bits wide
    EXPECT_EQ(s.find((0xFFFFFFFEull << 10) + 1023), CacheSets::kNoWay);  // the last line covered
    try {
        s.find(0xFFFFFFFFull << 10);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("beyond"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace rtsim
