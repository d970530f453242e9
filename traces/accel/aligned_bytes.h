#pragma once
// A byte buffer aligned to 64 bytes (one cache line), so the records of an image region can be
// read through their layout structs (alignas(64) nodes) without undefined behaviour.
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>

namespace rtsim {

class AlignedBytes {
public:
    static constexpr size_t kAlign = 64;

    AlignedBytes() = default;
    explicit AlignedBytes(size_t size) { resize(size); }
    AlignedBytes(const AlignedBytes& o) : AlignedBytes(o.m_size) {
        if (m_size) std::memcpy(m_data.get(), o.m_data.get(), m_size);
    }
    AlignedBytes& operator=(const AlignedBytes& o) {
        if (this != &o) *this = AlignedBytes(o);
        return *this;
    }
    AlignedBytes(AlignedBytes&&) noexcept = default;
    AlignedBytes& operator=(AlignedBytes&&) noexcept = default;

    /// Zero-filled storage of `size` bytes (contents are not kept).
    void resize(size_t size) {
        m_size = size;
        if (size == 0) {
            m_data.reset();
            return;
        }
        const size_t rounded = (size + kAlign - 1) / kAlign * kAlign;
        auto* p = static_cast<uint8_t*>(std::aligned_alloc(kAlign, rounded));
        if (!p) throw std::bad_alloc();
        std::memset(p, 0, rounded);
        m_data.reset(p);
    }
    size_t size() const { return m_size; }
    uint8_t* data() { return m_data.get(); }
    const uint8_t* data() const { return m_data.get(); }

private:
    struct Free {
        void operator()(uint8_t* p) const { std::free(p); }
    };
    std::unique_ptr<uint8_t, Free> m_data;
    size_t m_size = 0;
};

}  // namespace rtsim
