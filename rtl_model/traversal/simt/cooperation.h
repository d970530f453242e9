#pragma once
// Cooperative lanes (traversal.simt.cooperative; CoopRT, ISCA 2025; simt_unit.h): which ray a
// lane without one of its own helps. The SIMT unit and its functional warp profile (the analytic
// level's) both pick with this, so the two agree on what cooperation buys.
#include <cstdint>

namespace rtsim {

/// The lane in [first, first + lanes) whose ray a helper steps next: among those `eligible(l)`
/// (stepping this warp step, its next step of the warp's kind), the one whose ray has the most
/// stack entries not yet handed to a helper (`spare(l)`, at least one); `first + lanes` when none.
template <class Spare, class Eligible>
uint32_t pick_helped_lane(uint32_t first, uint32_t lanes, Spare&& spare, Eligible&& eligible) {
    uint32_t best = first + lanes;
    int most = 0;
    for (uint32_t l = first; l < first + lanes; ++l) {
        const int s = spare(l);
        if (s > most && eligible(l)) best = l, most = s;
    }
    return best;
}

}  // namespace rtsim
