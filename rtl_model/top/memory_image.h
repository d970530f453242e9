#pragma once
// The one memory image (DESIGN rule 3): the BVH nodes and triangles in the hardware layout of
// traces/bvh/hw_layout.h, at fixed addresses, plus the regions the rays, hits and spilled stacks
// live in. Documented in docs/model.md; every access of the model goes to one of these addresses.
#include <cstdint>
#include <vector>

#include "traces/bvh/hw_layout.h"
#include "traces/format/trace_format.h"

namespace rtsim {

struct MemoryMap {
    static constexpr uint64_t kNodes = 0x1'0000'0000ull;      ///< HwNode i at kNodes + 64 i
    static constexpr uint64_t kTriangles = 0x2'0000'0000ull;  ///< HwTriangle j at kTriangles + 48 j
    static constexpr uint64_t kRays = 0x3'0000'0000ull;       ///< RayRecord r at kRays + 40 r
    static constexpr uint64_t kHits = 0x4'0000'0000ull;       ///< HitRecord r at kHits + 20 r
    static constexpr uint64_t kStacks = 0x5'0000'0000ull;     ///< spilled stack entries, per context
    static constexpr uint64_t kRayBuffer = 0x6'0000'0000ull;  ///< ray states overflowing the ray buffer

    static uint64_t node(uint32_t i) { return kNodes + uint64_t(i) * sizeof(HwNode); }
    static uint64_t triangle(uint32_t j) { return kTriangles + uint64_t(j) * sizeof(HwTriangle); }
    static uint64_t ray(uint64_t r) { return kRays + r * sizeof(RayRecord); }
    static uint64_t hit(uint64_t r) { return kHits + r * sizeof(HitRecord); }
    /// Stack entry `depth` of context `context` (global index over all units).
    static uint64_t stack(uint64_t context, uint32_t depth, uint32_t entry_bytes) {
        return kStacks + (context * 64 + depth) * entry_bytes;
    }
    /// Overflow slot `slot` of the ray buffer (ray states of ray_state_bytes each).
    static uint64_t ray_buffer(uint64_t slot, uint32_t ray_state_bytes) { return kRayBuffer + slot * ray_state_bytes; }
};

/// The BVH image the model reads functionally (contents) and times by address.
struct MemoryImage {
    std::vector<HwNode> nodes;
    std::vector<HwTriangle> triangles;
    bool has_anyhit_triangles() const;
};

}  // namespace rtsim
