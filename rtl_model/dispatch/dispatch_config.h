#pragma once
// Configuration of dispatch: how rays are streamed from the trace and spread over the units.
#include <cstdint>

#include "rtl_model/common/choice.h"

namespace rtsim {

enum class DispatchPolicy : uint8_t { interleaved = 0, on_demand = 1 };
inline constexpr Choices<DispatchPolicy, 2> kDispatchPolicyChoices{{"interleaved", "on_demand"}};

struct DispatchConfig {
    uint32_t chunk_rays = 16384;          ///< rays read from the trace at a time (host memory bound)
    uint32_t latency = 2;                 ///< cycles to hand a ray to a free context (plus the ray fetch)
    DispatchPolicy policy = DispatchPolicy::interleaved;  ///< how rays are spread over the units
    uint32_t block_rays = 1;              ///< consecutive rays dealt to one unit (interleaved)

    template <class V>
    void visit(V& v) {
        v.field("chunk_rays", chunk_rays, "rays", "Rays streamed from the trace file per chunk", 64, 1u << 24);
        v.field("latency", latency, "cycles", "Cycles to assign a ray to a free context, before its fetch", 0, 1000);
        v.choice("policy", policy, kDispatchPolicyChoices, "interleaved: rays dealt to units in turn, blocks of block_rays, idle units steal; on_demand: the next ray to whichever unit asks first (depends on quantum_cycles)");
        v.field("block_rays", block_rays, "rays", "Consecutive rays dealt to one unit at a time (interleaved policy)", 1, 1u << 20);
    }
};

}  // namespace rtsim
