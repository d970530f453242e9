// Large arrays on 2 MiB pages (traces/common/huge_pages.h): zero-filled, aligned, usable as a
// vector's allocator, and (where the kernel offers transparent huge pages) actually backed by them.
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "traces/accel/aligned_bytes.h"
#include "traces/common/huge_pages.h"

namespace rtsim {
namespace {

bool all_zero(const uint8_t* p, size_t n) {
    for (size_t i = 0; i < n; ++i)
        if (p[i] != 0) return false;
    return true;
}

TEST(HugePages, SmallAllocationsAreZeroedAndLineAligned) {
    for (size_t bytes : {size_t(1), size_t(100), size_t(4096), kHugePageBytes - 1}) {
        EXPECT_FALSE(huge_mapped(bytes)) << bytes;
        auto* p = static_cast<uint8_t*>(huge_alloc(bytes));
        EXPECT_EQ(reinterpret_cast<uintptr_t>(p) % 64, 0u) << bytes;
        EXPECT_TRUE(all_zero(p, bytes)) << bytes;
        p[bytes - 1] = 7;
        huge_free(p, bytes);
    }
}

TEST(HugePages, LargeAllocationsAreZeroedAndPageAligned) {
    for (size_t bytes : {kHugePageBytes, 3 * kHugePageBytes + 12345}) {
        EXPECT_TRUE(huge_mapped(bytes)) << bytes;
        auto* p = static_cast<uint8_t*>(huge_alloc(bytes));
        EXPECT_EQ(reinterpret_cast<uintptr_t>(p) % 4096, 0u) << bytes;
        EXPECT_TRUE(all_zero(p, bytes)) << bytes;
        p[0] = 1;
        p[bytes - 1] = 2;
        EXPECT_EQ(p[bytes - 1], 2);
        huge_free(p, bytes);
    }
}

TEST(HugePages, LargeArraysStartAtStaggeredOffsetsIntoTheirHugePage) {
    // Arrays all starting 2 MiB-aligned would share their first records' cache sets.
    std::vector<void*> arrays;
    std::vector<uintptr_t> offsets;
    for (int i = 0; i < 4; ++i) {
        arrays.push_back(huge_alloc(kHugePageBytes));
        offsets.push_back(reinterpret_cast<uintptr_t>(arrays.back()) % kHugePageBytes);
    }
    for (int i = 1; i < 4; ++i) EXPECT_NE(offsets[i], offsets[i - 1]) << i;
    for (void* p : arrays) huge_free(p, kHugePageBytes);
}

TEST(HugePages, VectorKeepsItsContentsAcrossGrowth) {
    std::vector<uint32_t, HugePageAllocator<uint32_t>> v;
    const uint32_t n = uint32_t(3 * kHugePageBytes / sizeof(uint32_t));  // crosses the threshold
    for (uint32_t i = 0; i < n; ++i) v.push_back(i * 2654435761u);
    EXPECT_EQ(reinterpret_cast<uintptr_t>(v.data()) % 4096, 0u);
    for (uint32_t i = 0; i < n; i += 997) ASSERT_EQ(v[i], i * 2654435761u) << i;
    std::vector<uint32_t, HugePageAllocator<uint32_t>> copy = v;
    EXPECT_EQ(copy, v);
}

TEST(HugePages, AlignedBytesUsesThemForLargeRegions) {
    AlignedBytes big(5 * kHugePageBytes + 3);
    EXPECT_EQ(reinterpret_cast<uintptr_t>(big.data()) % 4096, 0u);
    EXPECT_TRUE(all_zero(big.data(), big.size()));
    big.data()[big.size() - 1] = 9;
    AlignedBytes copy = big;
    EXPECT_EQ(copy.size(), big.size());
    EXPECT_EQ(copy.data()[copy.size() - 1], 9);
    AlignedBytes unzeroed;
    unzeroed.resize(kHugePageBytes + 64, false);
    EXPECT_TRUE(all_zero(unzeroed.data() + kHugePageBytes, 64));  // padding and fresh pages
}

/// Kilobytes of AnonHugePages in the mapping containing `p` (/proc/self/smaps), -1 if unknown.
long anon_huge_kb(const void* p) {
    std::ifstream smaps("/proc/self/smaps");
    std::string line;
    const auto at = reinterpret_cast<uintptr_t>(p);
    bool inside = false;
    while (std::getline(smaps, line)) {
        uintptr_t lo = 0, hi = 0;
        char dash = 0;
        std::istringstream head(line);
        if (head >> std::hex >> lo >> dash >> hi && dash == '-') {
            inside = lo <= at && at < hi;
            continue;
        }
        if (inside && line.rfind("AnonHugePages:", 0) == 0) return std::stol(line.substr(14));
    }
    return -1;
}

TEST(HugePages, BackedByHugePagesWhenTheKernelOffersThem) {
    std::ifstream thp("/sys/kernel/mm/transparent_hugepage/enabled");
    std::string mode;
    std::getline(thp, mode);
    if (mode.find("[never]") != std::string::npos || mode.empty()) GTEST_SKIP() << "THP off: " << mode;
    const size_t bytes = 8 * kHugePageBytes;
    auto* p = static_cast<uint8_t*>(huge_alloc(bytes));
    for (size_t i = 0; i < bytes; i += 4096) p[i] = 1;  // fault every page in
    const long kb = anon_huge_kb(p);
    huge_free(p, bytes);
    if (kb < 0) GTEST_SKIP() << "no /proc/self/smaps";
    // Fragmented memory may refuse some; at least one 2 MiB page must have been given.
    EXPECT_GE(kb, 2048) << "mode " << mode;
}

}  // namespace
}  // namespace rtsim
