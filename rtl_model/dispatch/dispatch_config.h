#pragma once
// Configuration of dispatch: how rays are streamed from the trace and spread over the units.
#include <cstdint>

#include "rtl_model/common/choice.h"

namespace rtsim {

enum class DispatchPolicy : uint8_t { interleaved = 0, on_demand = 1 };
inline constexpr Choices<DispatchPolicy, 2> kDispatchPolicyChoices{{"interleaved", "on_demand"}};

/// The key rays are sorted by before they are dealt (rtl_model/dispatch/ray_sort.h).
enum class RaySort : uint8_t { none = 0, octant = 1, morton = 2, origin_direction = 3 };
inline constexpr Choices<RaySort, 4> kRaySortChoices{{"none", "octant", "morton", "origin_direction"}};

struct DispatchConfig {
    uint32_t chunk_rays = 16384;          ///< rays read from the trace at a time (host memory bound)
    uint32_t latency = 2;                 ///< cycles to hand a ray to a free context (plus the ray fetch)
    DispatchPolicy policy = DispatchPolicy::interleaved;  ///< how rays are spread over the units
    uint32_t block_rays = 1;              ///< consecutive rays dealt to one unit (interleaved)
    RaySort sort = RaySort::none;         ///< sorting stage's key (none: trace order)
    uint32_t sort_window = 4096;          ///< rays the sorting stage sorts together
    uint32_t sort_rays_per_cycle = 4;     ///< sorting stage throughput
    uint32_t sort_latency = 64;           ///< cycles from a window's last ray sorted to its first ray out

    template <class V>
    void visit(V& v) {
        v.field("chunk_rays", chunk_rays, "rays", "Rays streamed from the trace file per chunk", 64, 1u << 24);
        v.field("latency", latency, "cycles", "Cycles to assign a ray to a free context, before its fetch", 0, 1000);
        v.choice("policy", policy, kDispatchPolicyChoices, "interleaved: rays dealt to units in turn, blocks of block_rays, idle units steal; on_demand: the next ray to whichever unit asks first (depends on quantum_cycles)");
        v.field("block_rays", block_rays, "rays", "Consecutive rays dealt to one unit at a time (interleaved policy)", 1, 1u << 20);
        v.choice("sort", sort, kRaySortChoices, "Sorting stage before dealing: none (trace order), octant (direction signs), morton (origin Morton code), origin_direction (origin and direction bits interleaved)");
        v.field("sort_window", sort_window, "rays", "Rays the sorting stage sorts together (within each chunk)", 2, 1u << 20);
        v.field("sort_rays_per_cycle", sort_rays_per_cycle, "rays/cycle", "Sorting stage throughput", 1, 1024);
        v.field("sort_latency", sort_latency, "cycles", "Cycles from a sorted window's last ray to its first ray handed out", 0, 1u << 20);
    }
};

}  // namespace rtsim
