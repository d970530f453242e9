#pragma once
// Configuration of a cache (the per-unit L1s and the shared L2).
#include <cstdint>

namespace rtsim {

struct CacheConfig {
    uint32_t size_kib = 16;   ///< capacity
    uint32_t ways = 4;        ///< associativity
    uint32_t line_bytes = 64; ///< line size
    uint32_t latency = 4;     ///< hit latency in cycles
    uint32_t mshrs = 8;       ///< outstanding misses (miss status holding registers)
    uint32_t banks = 1;       ///< independently accessible banks (line-interleaved)
    uint32_t bank_cycles = 1; ///< cycles a bank is busy per access

    uint64_t lines() const { return uint64_t(size_kib) * 1024 / line_bytes; }

    template <class V>
    void visit(V& v) {
        v.field("size_kib", size_kib, "KiB", "Capacity", 1, 1u << 20);
        v.field("ways", ways, "ways", "Associativity (LRU replacement)", 1, 64);
        v.field("line_bytes", line_bytes, "bytes", "Line size (power of two, same at every level)", 16, 1024);
        v.field("latency", latency, "cycles", "Hit latency", 1, 1000);
        v.field("mshrs", mshrs, "entries", "Outstanding misses; a miss waits for a free MSHR", 1, 1024);
        v.field("banks", banks, "banks", "Line-interleaved banks, each serving one access per bank_cycles", 1, 256);
        v.field("bank_cycles", bank_cycles, "cycles", "Cycles a bank is busy per access", 1, 100);
    }
};

}  // namespace rtsim
