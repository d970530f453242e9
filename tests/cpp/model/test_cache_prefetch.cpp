// Prefetches in the cache (treelet prefetching, cache_prefetch.cpp) against hand-worked cases on
// the tiny cache of test_cache.cpp's kind: 2 sets x 2 ways of 256-byte lines, hit latency 4,
// 4 MSHRs (prefetches may hold 2), interconnect 2 cycles each way, next level 20 cycles. A miss
// issued at tag done i fills at i + 24.
#include <gtest/gtest.h>

#include "tiny_cache.h"

namespace rtsim {
namespace {

/// test_cache.cpp's tiny cache with 4 MSHRs, so that prefetches (which may hold 2) leave room.
struct PrefetchBench : Bench {
    PrefetchBench() : Bench(tiny_config(4), true) {}
};

TEST(CachePrefetch, CountsEveryPrefetchedLineOnce) {
    PrefetchBench b;
    EXPECT_EQ(b.prefetch(A, 0), 0u) << "taken: the prefetcher does not wait";
    EXPECT_EQ(b.read(A, 1), 28u) << "a read while A fills merges with the prefetch (late but useful)";
    EXPECT_EQ(b.prefetch(A, 2), 2u) << "A is there: redundant, nothing sent below";
    EXPECT_EQ(b.prefetch(D, 100), 100u);
    EXPECT_EQ(b.read(D, 200), 204u) << "filled at 128: a hit";
    EXPECT_EQ(b.prefetch(B, 300), 300u) << "set 0 = {A, B}";
    EXPECT_EQ(b.read(A, 350), 354u) << "A is used again: B is now the least recently used";
    EXPECT_EQ(b.read(C, 400), 428u) << "set 0 evicts B, never read: a useless prefetch";
    EXPECT_EQ(b.prefetch(E, 500), 500u) << "still unused at the end: resident";
    const nlohmann::json pf = b.prefetch_stats();
    EXPECT_EQ(pf["issued"], 4);
    EXPECT_EQ(pf["redundant"], 1);
    EXPECT_EQ(pf["useful"], 2);
    EXPECT_EQ(pf["late"], 1);
    EXPECT_EQ(pf["useless"], 1);
    EXPECT_EQ(pf["resident"], 1);
    EXPECT_EQ(pf["issued"].get<uint64_t>(),
              pf["useful"].get<uint64_t>() + pf["useless"].get<uint64_t>() + pf["resident"].get<uint64_t>());
    EXPECT_EQ(pf["below_bytes"], 4 * kLine);
    // Prefetches are not demand reads: the read counters see only the four reads.
    EXPECT_EQ(b.cache.stats_json(1000)["reads"], 4);
}

TEST(CachePrefetch, HoldsAtMostHalfTheMshrs) {
    PrefetchBench b;
    EXPECT_EQ(b.prefetch(A, 0), 0u);
    EXPECT_EQ(b.prefetch(D, 0), 0u);
    EXPECT_EQ(b.prefetch(B, 0), 28u) << "two prefetches in flight (2 of 4 MSHRs): retry when A fills";
    EXPECT_EQ(b.read(E, 1), 29u) << "a demand miss still finds a free MSHR: issue at 5, fill 29";
    EXPECT_EQ(b.prefetch_stats()["blocked"], 1);
    EXPECT_EQ(b.prefetch_stats()["issued"], 2);
}

TEST(CachePrefetch, PassesDownToItsTarget) {
    test::TestKernel kernel;
    test::FakeMemory dram{"dram", 20};
    Cache l2{"l2", tiny_config(4), true, 0, false, ServedBy::l2};
    Cache l1{"l1", tiny_config(4), true, 2};
    l2.next(dram);
    l1.next(l2);
    kernel.elaborate();
    EXPECT_EQ(l1.access({A, uint32_t(kLine), false, DataKind::node, 10, nullptr, true, ServedBy::l2}), 10u);
    ASSERT_EQ(dram.requests.size(), 1u);
    EXPECT_EQ(dram.requests[0].time, 16u) << "L1 to L2 2 cycles, L2 tag 4";
    EXPECT_FALSE(l1.stats_json(100).contains("prefetch")) << "the L1 only passed it on";
    EXPECT_EQ(l2.stats_json(100)["prefetch"]["issued"], 1);
    // A demand read then misses the L1 and hits the prefetched line in the L2.
    l1.access({A, 64, false, DataKind::node, 100});
    EXPECT_EQ(l2.stats_json(1000)["prefetch"]["useful"], 1);
    EXPECT_EQ(dram.requests.size(), 1u);
}

}  // namespace
}  // namespace rtsim
