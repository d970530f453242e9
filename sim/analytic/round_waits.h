#pragma once
// Rounds as time in the analysis's functional stepping (docs/fidelity.md, "Rounds as time"): a
// step whose slowest line is likely served below the L1 holds its context (or its lock-step
// group) for the rounds that line takes, so the rays left at the end of a run are the ones whose
// lines miss, as in the timed levels. A round is a step served by the L1 at the default machine
// (1 issue cycle, the L1's 4, the box pipeline's 8: 13); a line from the L2 adds its 20 cycles
// (2 rounds), one from DRAM the L2's and DRAM's 140 (10). Served below the L1: a first read in
// the unit's stream or a reuse past 4 x the default L1's 256 lines; from DRAM: a first read in
// all units' stream or a reuse past 4 x the default L2's 16,384 lines (the reuse distance counts
// accesses, the stack distance fewer). Fixed at the defaults, since one analysis serves every
// cache size and latency (analysis_cache.h); the closed form prices each step at the config's
// own.
#include <cstdint>
#include <vector>

#include "rtl_model/traversal/unit_kind.h"
#include "sim/analytic/reuse.h"

namespace rtsim {

/// Where a read is likely served (0: the L1, 1: the L2, 2: DRAM), from its reuse bins in the
/// unit's stream (ub, censored uc) and all units' stream (gb, gc); the rounds a step waits for
/// a line served there.
uint32_t served_level(int ub, bool uc, int gb, bool gc);
constexpr uint32_t kWaitRounds[3] = {0, 2, 10};
/// The rounds a step waits whose slowest line has this JointHistogram key (profile.h).
uint32_t wait_rounds(uint32_t key);

/// The reuse distances of a functional stepping's line reads, per unit and over all units, kept
/// only to tell each read's wait (lock-step groups, whose profiles keep no reuse histograms).
class LineWaits {
public:
    explicit LineWaits(uint32_t units) : m_unit_pos(units, 0) {}
    /// Where a read of `line` (a line number) by `unit` is likely served, and the rounds it waits.
    LineWait read(uint32_t unit, uint64_t line);

private:
    LastUse m_global, m_unit;
    uint64_t m_global_pos = 0;
    std::vector<uint64_t> m_unit_pos;
};

}  // namespace rtsim
