#include "traces/common/huge_pages.h"

#include <atomic>
#include <cstdlib>
#include <cstring>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace rtsim {
namespace {

constexpr size_t kSmallAlign = 64;

size_t round_up(size_t bytes, size_t to) { return (bytes + to - 1) / to * to; }

void* heap_alloc(size_t bytes, bool zero) {
    void* p = std::aligned_alloc(kSmallAlign, round_up(bytes == 0 ? 1 : bytes, kSmallAlign));
    if (!p) throw std::bad_alloc();
    if (zero) std::memset(p, 0, bytes);
    return p;
}

}  // namespace

#if defined(__linux__)
// mmap gives 4 KiB alignment only; map one huge page more than needed and unmap the ends, so the
// kernel can back every 2 MiB of the array with one page (THP needs 2 MiB-aligned ranges).
// Pages come zero-filled. madvise failing (THP disabled) leaves ordinary pages.
// Each array starts `colour` bytes into its first huge page, a different multiple of 68 KiB per
// allocation: on huge pages an address's low 21 bits pick its cache set, so arrays all starting
// 2 MiB-aligned would put their hot first records (the tree's top nodes, say) in the same L2
// sets. Measured on Sponza: 2 MiB-aligned starts cost primary rays about 5% against 4 KiB pages;
// staggered starts recover it and keep the incoherent rays' gain (docs/benchmarks.md).
void* huge_alloc(size_t bytes, bool zero) {
    if (!huge_mapped(bytes)) return heap_alloc(bytes, zero);
    static std::atomic<uint32_t> serial{0};
    const size_t colour = size_t((serial++ * 5u) % 16u) * 17u * 4096u;
    const size_t size = round_up(bytes + colour, kHugePageBytes);
    const size_t span = size + kHugePageBytes;
    void* raw = mmap(nullptr, span, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (raw == MAP_FAILED) throw std::bad_alloc();
    const auto base = reinterpret_cast<uintptr_t>(raw);
    const uintptr_t aligned = round_up(base, kHugePageBytes);
    if (aligned > base) munmap(raw, aligned - base);
    if (aligned + size < base + span) munmap(reinterpret_cast<void*>(aligned + size), base + span - aligned - size);
#ifdef MADV_HUGEPAGE
    madvise(reinterpret_cast<void*>(aligned), size, MADV_HUGEPAGE);
#endif
    return reinterpret_cast<void*>(aligned + colour);
}

void huge_free(void* p, size_t bytes) noexcept {
    if (!p) return;
    if (huge_mapped(bytes)) {
        const auto at = reinterpret_cast<uintptr_t>(p), base = at / kHugePageBytes * kHugePageBytes;
        munmap(reinterpret_cast<void*>(base), round_up(bytes + (at - base), kHugePageBytes));
    }
    else std::free(p);
}
#else
void* huge_alloc(size_t bytes, bool zero) { return heap_alloc(bytes, zero); }
void huge_free(void* p, size_t) noexcept { std::free(p); }
#endif

}  // namespace rtsim
