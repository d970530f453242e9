#pragma once
// The accelerator's memory map (docs/model.md): the acceleration structure's image regions at
// the addresses its descriptor gives (from 4 GiB up, traces/accel/accel_image.h), then the
// regions the model itself adds, each starting on a 4 GiB granule: ray records (read when a ray
// starts), hit records (written when it ends), spilled stack entries, ray-buffer overflow. Every
// access of the model goes to one of these addresses (docs/architecture.md, rule 3).
#include <algorithm>
#include <cstdint>

#include "traces/accel/accel_image.h"
#include "traces/format/trace_format.h"

namespace rtsim {

class MemoryMap {
public:
    /// image_end: AccelImage::end_address(); rays: rays in the trace; stack_owners: contexts (or
    /// rays, in treelet mode) that own a spill area of max_stack_entries x entry_bytes.
    MemoryMap(uint64_t image_end, uint64_t rays, uint64_t stack_owners, uint32_t max_stack_entries,
              uint32_t stack_entry_bytes)
        : m_rays(image_end),
          m_hits(next(m_rays, rays * sizeof(RayRecord))),
          m_stacks(next(m_hits, rays * sizeof(HitRecord))),
          m_ray_buffer(next(m_stacks, stack_owners * max_stack_entries * stack_entry_bytes)),
          m_stack_entries(max_stack_entries) {}

    uint64_t ray(uint64_t r) const { return m_rays + r * sizeof(RayRecord); }
    uint64_t hit(uint64_t r) const { return m_hits + r * sizeof(HitRecord); }
    /// Stack entry `depth` of spill-area owner `owner`.
    uint64_t stack(uint64_t owner, uint32_t depth, uint32_t entry_bytes) const {
        return m_stacks + (owner * m_stack_entries + depth) * entry_bytes;
    }
    /// Overflow slot `slot` of the ray buffer (ray states of `state_bytes` each).
    uint64_t ray_buffer(uint64_t slot, uint32_t state_bytes) const { return m_ray_buffer + slot * state_bytes; }

private:
    static uint64_t next(uint64_t base, uint64_t bytes) {
        return base + std::max(AccelImage::kGranule, round_up(bytes, AccelImage::kGranule));
    }
    uint64_t m_rays, m_hits, m_stacks, m_ray_buffer;
    uint32_t m_stack_entries;
};

}  // namespace rtsim
