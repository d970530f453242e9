#pragma once
// The on-chip traversal stack of a ray context (docs/model.md): `capacity` entries per ray; a
// push beyond them spills the oldest entry to memory (a posted write), a pop when the on-chip
// entries are gone reads the newest spilled one back (the ray waits for it). Shared by the
// traversal unit and the analytic level, so both count the same spill traffic.
#include <cstdint>

namespace rtsim {

/// Applies a stack change from `before` to `after` entries to a ray's on-chip/spilled split.
/// spill(slot) is called for each entry written to spill slot `slot`, fill(slot) for each read.
template <class Spill, class Fill>
void map_stack_change(uint32_t& local, uint32_t& spilled, int before, int after, uint32_t capacity, Spill&& spill,
                      Fill&& fill) {
    for (int i = before; i < after; ++i) {
        if (local < capacity) {
            ++local;
            continue;
        }
        spill(spilled);
        ++spilled;
    }
    for (int i = after; i < before; ++i) {
        if (local > 0) {
            --local;
            continue;
        }
        --spilled;
        fill(spilled);
    }
}

}  // namespace rtsim
