#pragma once
// The tiny cache the hand-worked cache tests use (test_cache.cpp, test_cache_prefetch.cpp):
// 2 sets x 2 ways of 256-byte lines, hit latency 4, interconnect 2 cycles each way, in front of a
// fake next level of 20 cycles. A miss issued at tag done i fills at i + 2 + 20 + 2 = i + 24.
#include <nlohmann/json.hpp>

#include "model_test_util.h"
#include "rtl_model/mem/cache.h"

namespace rtsim::test {

constexpr uint64_t kLine = 256;
/// Lines: A = 0 (set 0), D = 1 (set 1), B = 2 (set 0), E = 3 (set 1), C = 4 (set 0).
constexpr uint64_t A = 0 * kLine, D = 1 * kLine, B = 2 * kLine, E = 3 * kLine, C = 4 * kLine;

/// 1024 B = 2 sets x 2 ways x 256 B, latency 4, `mshrs` MSHRs, one bank.
inline CacheConfig tiny_config(uint32_t mshrs = 2) {
    CacheConfig c;
    c.size_kib = 1;
    c.ways = 2;
    c.line_bytes = uint32_t(kLine);
    c.latency = 4;
    c.mshrs = mshrs;
    c.banks = 1;
    c.bank_cycles = 1;
    return c;
}

/// The cache (prefetches may hold 2 of its MSHRs), its fake next level and a SystemC kernel.
struct Bench {
    TestKernel kernel;
    FakeMemory next{"next", 20};
    Cache cache;
    Bench(const CacheConfig& config, bool mshrs) : cache("cache", config, mshrs, 2) {
        cache.next(next);
        kernel.elaborate();
    }
    /// A line prefetch at cycle t (returns when it is taken).
    Cycle prefetch(uint64_t addr, Cycle t) {
        return cache.access({addr, uint32_t(kLine), false, DataKind::node, t, nullptr, true, ServedBy::l1});
    }
    /// A 64-byte node read at cycle t (returns when its data is there).
    Cycle read(uint64_t addr, Cycle t) { return cache.access({addr, 64, false, DataKind::node, t}); }
    nlohmann::json prefetch_stats() const { return cache.stats_json(1000)["prefetch"]; }
};

}  // namespace rtsim::test

namespace rtsim {
namespace {
// Its names as the two cache tests that include it use them (test_cache.cpp,
// test_cache_prefetch.cpp).
using test::A;
using test::B;
using test::Bench;
using test::C;
using test::D;
using test::E;
using test::kLine;
using test::tiny_config;
}  // namespace
}  // namespace rtsim
