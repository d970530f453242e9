#include "sim/analytic/round_waits.h"

#include "sim/analytic/profile.h"

namespace rtsim {

uint32_t served_level(int ub, bool uc, int gb, bool gc) {
    // The first bins whose distances all lie past 4 x the default L1's and L2's lines.
    static const int l1_bin = DistanceBins::bin(4 * 256) + 1, l2_bin = DistanceBins::bin(4 * 16384) + 1;
    if (gc || gb >= l2_bin) return 2;
    if (uc || ub >= l1_bin) return 1;
    return 0;
}

uint32_t wait_rounds(uint32_t key) {
    int ub, gb;
    bool uc, gc;
    JointHistogram::unpack(key, &ub, &uc, &gb, &gc);
    return kWaitRounds[served_level(ub, uc, gb, gc)];
}

LineWait LineWaits::read(uint32_t unit, uint64_t line) {
    const uint64_t gpos = ++m_global_pos, upos = ++m_unit_pos[unit];
    const uint64_t gprev = m_global.exchange(line, gpos), uprev = m_unit.exchange(line << 16 | unit, upos);
    const bool gc = gprev == ~0ull, uc = uprev == ~0ull;
    const uint32_t level =
        served_level(DistanceBins::bin(uc ? upos : upos - uprev), uc, DistanceBins::bin(gc ? gpos : gpos - gprev), gc);
    return {kWaitRounds[level], level};
}

}  // namespace rtsim
