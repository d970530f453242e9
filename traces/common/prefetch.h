#pragma once
// Host-cache prefetch of a byte range (every 64-byte line it touches). Steppers call it when they
// plan a step: whoever drives them times the plan first (the model interleaves other rays), so
// execute() finds the data in the host's cache (docs/benchmarks.md, "Simulator speed").
#include <cstddef>

namespace rtsim {

inline void prefetch_range(const void* data, size_t bytes) {
    if (bytes == 0) return;
    const char* first = static_cast<const char*>(data);
    for (size_t b = 0; b < bytes; b += 64) __builtin_prefetch(first + b);
    __builtin_prefetch(first + bytes - 1);  // the last line when the range is not line-aligned
}

}  // namespace rtsim
