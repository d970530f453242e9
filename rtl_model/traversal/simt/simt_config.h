#pragma once
// The SIMT unit kind's own config section, traversal.simt (simt_unit.h).
#include <cstdint>

#include "rtl_model/common/choice.h"

namespace rtsim {

/// Which operation kind a SIMT warp runs next (Aila & Laine 2009, "Understanding the efficiency
/// of ray traversal on GPUs", section 2): while_while keeps the kind it ran while any lane still
/// needs it (the inner loops of while-while traversal), if_if takes the next kind any lane needs
/// in turn each warp step (one step of each branch per loop iteration).
enum class SimtPolicy : uint8_t { while_while = 0, if_if = 1 };
inline constexpr Choices<SimtPolicy, 2> kSimtPolicyChoices{{"while_while", "if_if"}};

/// When a SIMT lane whose ray finished gets a new one: at its warp's next step (lane: persistent
/// threads that fetch work as they finish), or only once every lane of its warp has finished
/// (warp: the whole warp retires and is relaunched).
enum class SimtRefill : uint8_t { lane = 0, warp = 1 };
inline constexpr Choices<SimtRefill, 2> kSimtRefillChoices{{"lane", "warp"}};

struct SimtConfig {
    uint32_t lanes = 8;  ///< rays per warp, stepping in lock-step
    SimtPolicy policy = SimtPolicy::while_while;  ///< which operation kind a warp runs next
    SimtRefill refill = SimtRefill::lane;         ///< when a finished lane takes a new ray
    bool cooperative = false;  ///< idle lanes step busy lanes' rays (CoopRT; simt_unit.h)

    template <class V>
    void visit(V& v) {
        v.field("lanes", lanes, "rays", "Rays per warp in lock-step; traversal.ray_contexts is a whole number of warps (0 there: 16 rounded up to whole warps)", 4, 64);
        v.choice("policy", policy, kSimtPolicyChoices, "while_while (a warp keeps its operation kind while any lane needs it) or if_if (kinds in turn each warp step), Aila & Laine 2009");
        v.choice("refill", refill, kSimtRefillChoices, "lane (a finished lane takes a new ray at its warp's next step) or warp (only when every lane of the warp has finished)");
        v.flag("cooperative", cooperative, "Cooperative lanes (CoopRT, ISCA 2025): a lane without a ray of its own steps another lane's ray in the same warp step, taking an entry of that ray's traversal stack (docs/execution_models.md, 'Cooperative lanes')");
    }
};

}  // namespace rtsim
