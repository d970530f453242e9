#pragma once
// Counter-based random numbers: a value depends only on (seed, stream, index), never on
// thread scheduling, so traces are bit-identical whatever the thread count.
#include <cstdint>

namespace rtsim {

/// 64-bit mix (SplitMix64 finaliser, Steele et al. 2014).
uint64_t mix64(uint64_t x);
/// Hash of a key tuple, well mixed.
uint64_t hash_combine(uint64_t seed, uint64_t a, uint64_t b = 0, uint64_t c = 0);
/// Uniform float in [0, 1) from a hash (24 bits of mantissa).
float hash_to_unit(uint64_t h);

/// A tiny stream generator seeded from a hash: next() yields uniform floats in [0, 1).
class Rng {
public:
    explicit Rng(uint64_t state) : m_state(state) {}
    float next() {
        m_state += 0x9E3779B97F4A7C15ull;
        return hash_to_unit(mix64(m_state));
    }

private:
    uint64_t m_state;
};

}  // namespace rtsim
