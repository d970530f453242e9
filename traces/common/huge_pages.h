#pragma once
// Large arrays on 2 MiB pages. The tracer's node and triangle arrays (tens of MB on Sponza) are
// read in an order no prefetcher follows, so on 4 KiB pages nearly every node fetch also misses
// the TLB. Embree allocates its BVH with mmap and madvise(MADV_HUGEPAGE) (common/sys/alloc.cpp,
// os_malloc) for the same reason; this does the same for rtsim's large arrays. Where the kernel
// does not give huge pages (THP "never", another OS) the memory is ordinary pages: only the speed
// differs, never the contents.
#include <cstddef>
#include <cstdint>
#include <new>

namespace rtsim {

/// The huge page size. It is also the threshold (huge_mapped): an allocation of at least one
/// huge page is mapped 2 MiB-aligned and advised as huge pages; smaller ones come from the heap
/// (a huge page for a few KB would waste memory).
constexpr size_t kHugePageBytes = size_t(2) << 20;

/// `bytes` of storage aligned to at least 64 bytes (4 KiB when huge_mapped(bytes): on
/// huge pages, starting at a varying offset into the first one, huge_pages.cpp),
/// zero-filled (always so when mapped: fresh pages are zero; zero = false spares a small block
/// the memset). Throws std::bad_alloc. Free with huge_free and the same `bytes`.
void* huge_alloc(size_t bytes, bool zero = true);
void huge_free(void* p, size_t bytes) noexcept;

/// True when huge_alloc(bytes) maps whole 2 MiB pages (the caller may skip zeroing them): the
/// one place that decides which allocations go on huge pages.
inline bool huge_mapped(size_t bytes) { return bytes >= kHugePageBytes; }

/// std::allocator for large vectors (the build's temporaries): same as huge_alloc, so a
/// vector's storage moves to huge pages once huge_mapped says so.
template <class T>
struct HugePageAllocator {
    using value_type = T;
    HugePageAllocator() = default;
    template <class U>
    HugePageAllocator(const HugePageAllocator<U>&) noexcept {}
    T* allocate(size_t n) {
        if (n > size_t(-1) / sizeof(T)) throw std::bad_alloc();
        return static_cast<T*>(huge_alloc(n * sizeof(T), false));
    }
    void deallocate(T* p, size_t n) noexcept { huge_free(p, n * sizeof(T)); }
    template <class U>
    bool operator==(const HugePageAllocator<U>&) const noexcept { return true; }
    template <class U>
    bool operator!=(const HugePageAllocator<U>&) const noexcept { return false; }
};

}  // namespace rtsim
