// The analytic profiler's hot-loop tables against plain standard containers: LastUse (last
// position per line, through growth and clears) and KeyCounts (counts per key, through growth
// and drains). Both are exact; only their speed differs from the containers.
#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <unordered_map>

#include "sim/analytic/key_counts.h"
#include "sim/analytic/reuse.h"
#include "traces/common/rng.h"

namespace rtsim {
namespace {

TEST(LastUseTable, ExchangesAsAMapDoesThroughGrowthAndClears) {
    LastUse table(16);  // small, so it grows many times
    std::unordered_map<uint64_t, uint64_t> want;
    Rng rng(7);
    for (int round = 0; round < 3; ++round) {
        for (uint64_t pos = 1; pos <= 50000; ++pos) {
            // Line numbers as the profiler makes them: image addresses >> 6, some with a unit.
            const uint64_t line = (uint64_t(1) << 26) + uint64_t(rng.next() * 20000.0f);
            const uint64_t key = rng.next() < 0.5f ? line : line << 16 | uint64_t(rng.next() * 8.0f);
            const auto it = want.find(key);
            const uint64_t expected = it == want.end() ? ~0ull : it->second;
            ASSERT_EQ(table.exchange(key, pos), expected) << "round " << round << ", position " << pos;
            want[key] = pos;
        }
        EXPECT_EQ(table.size(), want.size());
        table.clear();
        want.clear();
        EXPECT_EQ(table.size(), 0u);
    }
}

TEST(KeyCountsTable, CountsAsAMapDoesThroughGrowthAndDrains) {
    KeyCounts counts;
    Rng rng(11);
    for (int round = 0; round < 2; ++round) {
        std::map<uint32_t, uint64_t> want;
        for (int i = 0; i < 200000; ++i) {
            // Histogram keys (18 bits), a few hot ones and a long tail, and key 0.
            const uint32_t key =
                rng.next() < 0.7f ? uint32_t(rng.next() * 16.0f) : uint32_t(rng.next() * 262143.0f);
            counts.add(key);
            want[key] += 1;
        }
        std::map<uint32_t, uint64_t> got;
        counts.drain([&](uint32_t key, uint64_t n) {
            EXPECT_EQ(got.count(key), 0u) << "key " << key << " drained twice";
            got[key] = n;
        });
        EXPECT_EQ(got, want);
        uint64_t left = 0;
        counts.drain([&](uint32_t, uint64_t n) { left += n; });
        EXPECT_EQ(left, 0u) << "a drain forgets what it drained";
    }
}

}  // namespace
}  // namespace rtsim
