#pragma once
// A byte buffer aligned to 64 bytes (one cache line), so the records of an image region can be
// read through their layout structs (alignas(64) nodes) without undefined behaviour. Buffers of
// 2 MiB and more are mapped on huge pages (traces/common/huge_pages.h): the tracer's node and
// triangle regions are read in an order no prefetcher follows, and on 4 KiB pages most of those
// reads would also miss the TLB.
#include <cstdint>
#include <cstring>
#include <memory>

#include "traces/common/huge_pages.h"

namespace rtsim {

class AlignedBytes {
public:
    static constexpr size_t kAlign = 64;

    AlignedBytes() = default;
    explicit AlignedBytes(size_t size) { resize(size); }
    AlignedBytes(const AlignedBytes& o) : AlignedBytes() {
        resize(o.m_size, false);
        if (m_size) std::memcpy(m_data.get(), o.m_data.get(), m_size);
    }
    AlignedBytes& operator=(const AlignedBytes& o) {
        if (this != &o) *this = AlignedBytes(o);
        return *this;
    }
    AlignedBytes(AlignedBytes&&) noexcept = default;
    AlignedBytes& operator=(AlignedBytes&&) noexcept = default;

    /// Storage of `size` bytes (contents are not kept), zero-filled unless the caller is about to
    /// overwrite every byte (zero = false: a region read from a trace; the padding past the end
    /// is zero either way).
    void resize(size_t size, bool zero = true) {
        m_size = size;
        m_data.reset();
        if (size == 0) return;
        const size_t rounded = (size + kAlign - 1) / kAlign * kAlign;
        m_data = std::unique_ptr<uint8_t, Free>(static_cast<uint8_t*>(huge_alloc(rounded, zero)), Free{rounded});
        if (!zero) std::memset(m_data.get() + size, 0, rounded - size);
    }
    size_t size() const { return m_size; }
    uint8_t* data() { return m_data.get(); }
    const uint8_t* data() const { return m_data.get(); }

private:
    struct Free {
        size_t bytes;  // value-initialised to 0 by unique_ptr's default constructor
        void operator()(uint8_t* p) const { huge_free(p, bytes); }
    };
    std::unique_ptr<uint8_t, Free> m_data;
    size_t m_size = 0;
};

}  // namespace rtsim
