#include "traces/common/huge_pages.h"

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
void* huge_alloc(size_t bytes, bool zero) {
    if (!huge_mapped(bytes)) return heap_alloc(bytes, zero);
    const size_t size = round_up(bytes, kHugePageBytes);
    const size_t span = size + kHugePageBytes;
    void* raw = mmap(nullptr, span, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (raw == MAP_FAILED) throw std::bad_alloc();
    const auto base = reinterpret_cast<uintptr_t>(raw);
    const uintptr_t aligned = round_up(base, kHugePageBytes);
    if (aligned > base) munmap(raw, aligned - base);
    if (aligned + size < base + span) munmap(reinterpret_cast<void*>(aligned + size), base + span - aligned - size);
    void* p = reinterpret_cast<void*>(aligned);
#ifdef MADV_HUGEPAGE
    madvise(p, size, MADV_HUGEPAGE);
#endif
    return p;
}

void huge_free(void* p, size_t bytes) noexcept {
    if (!p) return;
    if (huge_mapped(bytes)) munmap(p, round_up(bytes, kHugePageBytes));
    else std::free(p);
}
#else
void* huge_alloc(size_t bytes, bool zero) { return heap_alloc(bytes, zero); }
void huge_free(void* p, size_t) noexcept { std::free(p); }
#endif

}  // namespace rtsim
