#pragma once
// Division and remainder by a divisor fixed at construction (window cycles, bank counts, channel
// interleaving): a shift and a mask when the divisor is a power of two (the usual configs), a
// hardware division otherwise. The model divides on every access, and a 64-bit division costs
// tens of cycles where a shift costs one (docs/benchmarks.md "Simulator speed").
#include <cstdint>

namespace rtsim {

class Divider {
public:
    explicit Divider(uint64_t divisor = 1) : m_divisor(divisor ? divisor : 1) {
        if ((m_divisor & (m_divisor - 1)) == 0)
            while ((uint64_t(1) << m_shift) < m_divisor) ++m_shift;
        else m_shift = -1;
    }
    uint64_t div(uint64_t x) const { return m_shift >= 0 ? x >> m_shift : x / m_divisor; }
    uint64_t mod(uint64_t x) const { return m_shift >= 0 ? x & (m_divisor - 1) : x % m_divisor; }

private:
    uint64_t m_divisor;
    int m_shift = 0;
};

}  // namespace rtsim
