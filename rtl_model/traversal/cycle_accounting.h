#pragma once
// Cycle accounting of ray contexts (docs/stats.md, "Cycle accounting"): every cycle of every ray
// context of a run is in exactly one use, so the uses of a unit sum to ray_contexts x the run's
// cycles (tested). It says where time goes: issuing, each pipeline kind, each memory level,
// MSHRs full, stack spills, the ray buffer, or no ray to run.
#include <algorithm>
#include <array>
#include <cstdint>

#include <nlohmann/json.hpp>

#include "rtl_model/common/interfaces.h"
#include "traces/accel/step_plan.h"

namespace rtsim {

/// What a ray context spends a cycle on. Append only (names are stats keys).
enum class CycleUse : uint8_t {
    issue = 0,      ///< ready, waiting for the unit's scheduler to take its step
    dispatch,       ///< receiving a ray from dispatch
    l1_hit,         ///< waiting for data the L1 served
    l2,             ///< waiting for data the L2 served (an L1 miss)
    dram,           ///< waiting for data DRAM served (an L2 miss)
    l1_mshr_full,   ///< waiting for a free L1 MSHR
    l2_mshr_full,   ///< waiting for a free L2 MSHR
    stack,          ///< waiting for spilled stack entries read back from memory
    ray_buffer,     ///< treelet mode: waiting for a ray's state from the ray buffer
    starved,        ///< no ray to run while the workload still has rays for later
    tail,           ///< no ray to run: the workload has run out (the end of the run)
    idle_lane,      ///< SIMT: a lane with a ray (or waiting for its warp) masked off by divergence
    pipe_first,     ///< first of kOpKindCount uses: waiting for the pipeline of each operation kind
};
constexpr int kCycleUseCount = int(CycleUse::pipe_first) + kOpKindCount;

inline CycleUse pipe_use(OpKind kind) { return CycleUse(int(CycleUse::pipe_first) + int(kind)); }
/// "issue", ..., "pipe_box", "pipe_triangle", ...
std::string cycle_use_name(CycleUse use);

/// Context-cycles per use.
class CycleAccount {
public:
    void add(CycleUse use, Cycle cycles) { m_cycles[size_t(use)] += cycles; }
    uint64_t operator[](CycleUse use) const { return m_cycles[size_t(use)]; }
    uint64_t total() const;
    CycleAccount& operator+=(const CycleAccount& o);
    /// {use: cycles} for the uses that occurred (every non-pipeline use but idle_lane always appears;
/// idle_lane and the pipelines' uses appear when they occurred).
    nlohmann::json to_json() const;

private:
    std::array<uint64_t, kCycleUseCount> m_cycles{};
};

/// The time of a read from `start` to `ready`, split by where it went (MSHR waits first, then the
/// level that served it), into `account`. Inline: every step of every unit calls it.
inline void account_memory(CycleAccount& account, Cycle start, Cycle ready, const AccessInfo& info) {
    Cycle left = ready > start ? ready - start : 0;
    const Cycle l1 = std::min(info.mshr_wait[0], left);
    account.add(CycleUse::l1_mshr_full, l1);
    left -= l1;
    const Cycle l2 = std::min(info.mshr_wait[1], left);
    account.add(CycleUse::l2_mshr_full, l2);
    left -= l2;
    const CycleUse level = info.level == ServedBy::dram ? CycleUse::dram
                           : info.level == ServedBy::l2 ? CycleUse::l2
                                                        : CycleUse::l1_hit;
    account.add(level, left);
}

}  // namespace rtsim
