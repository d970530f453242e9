// The cache against a hand-worked access sequence: a tiny cache (2 sets x 2 ways of 256-byte
// lines, hit latency 4, 2 MSHRs, interconnect 2 cycles each way) in front of a fake next level
// with a fixed latency of 20 cycles. A miss issued at cycle i (tag done, MSHR free) reaches the
// next level at i + 2 and fills at i + 2 + 20 + 2 = i + 24.
#include <gtest/gtest.h>

#include "tiny_cache.h"

namespace rtsim {
namespace {

struct Step {
    Cycle time;
    uint64_t addr;
    uint32_t bytes;
    bool write;
    DataKind kind;
    Cycle expect;      ///< cycle the access returns
    const char* why;   ///< the hand-worked reasoning
};

TEST(Cache, HandWorkedSequence) {
    Bench b(tiny_config(), true);
    const DataKind N = DataKind::node, T = DataKind::triangle, R = DataKind::ray, H = DataKind::hit,
                   S = DataKind::stack;
    // LRU order is by last use (hits, merged hits and fills all count as a use).
    const Step steps[] = {
        {0, A, 64, false, N, 28, "miss; MSHR0 free: issue at tag done 4, fill 4 + 24 = 28"},
        {1, A + 64, 64, false, N, 28, "A in flight: merged miss returns A's fill time"},
        {2, B, 64, false, N, 30, "miss; MSHR1 free: issue 6, fill 30"},
        {3, D, 96, false, T, 52, "miss; both MSHRs busy (28, 30): waits 21 cycles for MSHR0, "
                                 "issue 28, fill 52"},
        {40, A, 64, false, N, 44, "hit: A filled at 28 <= tag done 44; A becomes most recent in set 0"},
        {41, C, 64, false, N, 69, "miss; set 0 = {A (used at 40), B (used at 2)}: LRU victim B; "
                                  "MSHR1 free at 30: issue 45, fill 69"},
        {42, B, 64, false, N, 76, "B was evicted: miss; victim A (older than C); MSHRs at 52, 69: "
                                  "waits 6 for MSHR0, issue 52, fill 76"},
        {43, A, 64, false, N, 93, "A was evicted: miss; victim C; MSHRs at 76, 69: waits 22 for MSHR1, "
                                  "issue 69, fill 93"},
        {100, D + 16, 20, true, H, 104, "write hit of line D: posted write-through, done at tag done 104"},
        {101, E, 8, true, S, 105, "write miss of line E: no allocation, done at tag done 105"},
        {102, E, 8, false, S, 130, "E was not allocated by the write: miss; MSHR0 free (76): "
                                   "issue 106, fill 130"},
        {200, E + 232, 48, false, R, 228, "spans E (hit at 204) and C (evicted: miss, victim B, "
                                         "MSHR1 free: issue 204, fill 228)"},
    };
    for (const Step& s : steps) {
        MemRequest req{s.addr, s.bytes, s.write, s.kind, s.time};
        EXPECT_EQ(b.cache.access(req), s.expect) << "access at cycle " << s.time << ": " << s.why;
    }

    // What the next level saw: every line fill (whole lines) and every write (the written bytes).
    struct Down {
        uint64_t addr;
        uint32_t bytes;
        bool write;
        DataKind kind;
        Cycle time;
    };
    const Down expected[] = {
        {A, 256, false, N, 6},  {B, 256, false, N, 8},   {D, 256, false, T, 30}, {C, 256, false, N, 47},
        {B, 256, false, N, 54}, {A, 256, false, N, 71},  {D + 16, 20, true, H, 106}, {E, 8, true, S, 107},
        {E, 256, false, S, 108}, {C, 256, false, R, 206},
    };
    ASSERT_EQ(b.next.requests.size(), std::size(expected));
    for (size_t i = 0; i < std::size(expected); ++i) {
        const MemRequest& r = b.next.requests[i];
        EXPECT_EQ(r.addr, expected[i].addr) << "request " << i;
        EXPECT_EQ(r.bytes, expected[i].bytes) << "request " << i;
        EXPECT_EQ(r.write, expected[i].write) << "request " << i;
        EXPECT_EQ(r.kind, expected[i].kind) << "request " << i;
        EXPECT_EQ(r.time, expected[i].time) << "request " << i;
    }

    // Per-kind counters: reads and read bytes per line touched; hits and merged misses apart.
    const MemStats& st = b.cache.stats();
    EXPECT_EQ(st[N].reads, 7u);
    EXPECT_EQ(st[N].read_hits, 1u);
    EXPECT_EQ(st[N].merged, 1u);
    EXPECT_EQ(st[N].read_bytes, 7u * 64);
    EXPECT_EQ(st[N].writes, 0u);
    EXPECT_EQ(st[T].reads, 1u);
    EXPECT_EQ(st[T].read_hits, 0u);
    EXPECT_EQ(st[T].read_bytes, 96u);
    EXPECT_EQ(st[H].writes, 1u);
    EXPECT_EQ(st[H].write_bytes, 20u);
    EXPECT_EQ(st[H].reads, 0u);
    EXPECT_EQ(st[S].writes, 1u);
    EXPECT_EQ(st[S].write_bytes, 8u);
    EXPECT_EQ(st[S].reads, 1u);
    EXPECT_EQ(st[S].read_hits, 0u);
    EXPECT_EQ(st[R].reads, 2u);  // one per line of the spanning access
    EXPECT_EQ(st[R].read_hits, 1u);
    EXPECT_EQ(st[R].read_bytes, 48u);  // 24 bytes in each line
    const MemCounters total = st.total();
    EXPECT_EQ(total.reads, 11u);
    EXPECT_EQ(total.writes, 2u);

    const nlohmann::json j = b.cache.stats_json(1000);
    EXPECT_EQ(j["evictions"], 4);  // B, A, C, B
    EXPECT_EQ(j["mshr_stall_cycles"], 21 + 6 + 22);
    EXPECT_EQ(j["reads"], 11);
    EXPECT_DOUBLE_EQ(j["hit_rate"].get<double>(), 3.0 / 11.0);  // 2 hits + 1 merged of 11 reads
    EXPECT_EQ(j["by_kind"]["node"]["merged"], 1);
}

TEST(Cache, WarmedLinesHitWithoutTrafficOrStatsAndObeyLru) {
    // Functional warming (sampling): warm() makes lines present and most recently used, as a
    // read would, but sends nothing below and counts nothing.
    Bench b(tiny_config(), true);
    b.cache.warm(A, 64);
    b.cache.warm(B + 200, 100);  // spans lines B (set 0) and E (set 1)
    EXPECT_TRUE(b.next.requests.empty());
    EXPECT_EQ(b.cache.stats_json(1000)["reads"], 0);
    EXPECT_EQ(b.cache.access({E, 64, false, DataKind::node, 0}), 4u) << "E warmed: hit at tag time";
    EXPECT_EQ(b.cache.access({A, 64, false, DataKind::node, 1}), 5u) << "A warmed: hit; B is now LRU in set 0";
    b.cache.warm(C, 64);  // set 0 is full: evicts B, the least recently used
    EXPECT_EQ(b.cache.access({A, 64, false, DataKind::node, 2}), 6u) << "A survives";
    EXPECT_EQ(b.cache.access({B, 64, false, DataKind::node, 3}), 31u) << "B was evicted by the warm C: miss, 7 + 24";
    EXPECT_EQ(b.next.requests.size(), 1u);
    EXPECT_EQ(b.cache.stats_json(1000)["reads"], 4);
}

TEST(Cache, WithoutMshrsMissesNeverWait) {
    // A shared cache (the L2) accessed out of time order does not model MSHRs: three misses at
    // once all go down at their tag time.
    Bench b(tiny_config(), false);
    EXPECT_EQ(b.cache.access({A, 64, false, DataKind::node, 0}), 28u);
    EXPECT_EQ(b.cache.access({B, 64, false, DataKind::node, 0}), 28u);
    EXPECT_EQ(b.cache.access({D, 64, false, DataKind::node, 0}), 28u);
    EXPECT_EQ(b.cache.stats_json(1000)["mshr_stall_cycles"], 0);
    EXPECT_EQ(b.cache.stats_json(1000)["config"]["mshrs"], 0);
}

TEST(Cache, EachBankServesOneAccessPerBankCycles) {
    CacheConfig c = tiny_config();
    c.banks = 2;
    c.bank_cycles = 3;
    Bench b(c, true);
    // Warm A (bank 0) and D (bank 1).
    b.cache.access({A, 64, false, DataKind::node, 0});
    b.cache.access({D, 64, false, DataKind::node, 0});
    // 200 hits to bank 0 at cycle 1000 take 200 x 3 cycles of that bank (the bank calendar is
    // exact per window, so allow one window of slack either way).
    Cycle last = 0;
    for (int i = 0; i < 200; ++i) last = std::max(last, b.cache.access({A, 64, false, DataKind::node, 1000}));
    EXPECT_NEAR(double(last), 1000.0 + 199 * 3 + 4, 48.0);
    // Bank 1 is not slowed by bank 0's queue.
    EXPECT_EQ(b.cache.access({D, 64, false, DataKind::node, 1000}), 1004u);
    EXPECT_EQ(b.cache.stats()[DataKind::node].read_hits, 201u);
}

}  // namespace
}  // namespace rtsim

namespace rtsim {
namespace {
/// A DRAM stand-in: fixed latency, reports that it served the read.
class FakeDram : public sc_core::sc_module, public MemIf {
public:
    explicit FakeDram(sc_core::sc_module_name name) : sc_core::sc_module(name) {}
    Cycle access(const MemRequest& req) override {
        if (req.info) req.info->level = ServedBy::dram;
        return req.time + 100;
    }
};

TEST(Cache, AccessInfoSaysWhereAReadsTimeWent) {
    test::TestKernel kernel;
    FakeDram dram("dram");
    CacheConfig one_mshr = tiny_config();
    one_mshr.mshrs = 1;
    Cache l2("l2", tiny_config(), true, 0, false, ServedBy::l2);
    Cache l1("l1", one_mshr, true, 2, false, ServedBy::l1);
    l1.next(l2);
    l2.next(dram);
    kernel.elaborate();
    auto read = [&](uint64_t addr, Cycle time, AccessInfo* info) {
        return l1.access({addr, 8, false, DataKind::node, time, info});
    };
    AccessInfo a, b, c, d;
    const Cycle first = read(0, 0, &a);  // misses both: DRAM
    EXPECT_EQ(a.level, ServedBy::dram);
    EXPECT_EQ(a.mshr_wait[0] + a.mshr_wait[1], 0u);
    read(kLine * 4, 1, &b);  // another line while the L1's only MSHR is busy: waits for it
    EXPECT_EQ(b.level, ServedBy::dram);
    EXPECT_GT(b.mshr_wait[0], 0u);
    EXPECT_EQ(read(0, first + 10, &c), first + 10 + 4);  // now an L1 hit
    EXPECT_EQ(c.level, ServedBy::l1);
    read(0, 2, &d);  // the first line again, still being filled: waits for the DRAM fill
    EXPECT_EQ(d.level, ServedBy::dram);
    const nlohmann::json j = l1.stats_json(first + 100, true);
    EXPECT_GT(j["mshr_busy_cycles"].get<uint64_t>(), 0u);
    EXPECT_GT(j["mshr_utilization"].get<double>(), 0.0);
    EXPECT_TRUE(j["mshr_utilization_over_time"].is_array());
}

}  // namespace
}  // namespace rtsim
