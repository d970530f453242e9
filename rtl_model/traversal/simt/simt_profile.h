#pragma once
// The SIMT kind's warps stepped functionally, for the analytic level (unit_kind.h, GroupProfile):
// the warp-step rules of simt_unit.h (one operation kind per warp step by traversal.simt.policy,
// lanes refilled by traversal.simt.refill, new rays' records fetched in a warp step of their
// own, reads coalesced per line) without time: every warp takes one warp step in turn, and a
// unit's lanes take the rays dispatch deals that unit, in order, when the policy lets them.
// With treelet scheduling (GroupSetup::treelets) lanes take rays from their warp's treelet queue
// instead, lanes whose next step is in another treelet park there, and a warp left without rays
// forms again from the largest queue, as simt_unit.cpp's treelet mode does.
// Without treelet queues a warp whose step read a line likely served below the L1 waits the
// rounds that line takes (GroupSetup::line_wait, the analysis's rounds as time), so the warps
// left at the end are the ones whose lanes miss, as in the timed levels.
#include <cstdint>
#include <vector>

#include "rtl_model/traversal/unit_kind.h"

namespace rtsim {

GroupProfile simt_group_profile(const Accel& accel, const StepOptions& step, const TraversalConfig& traversal,
                                const std::vector<std::vector<RayJob>>& rays_by_unit, const GroupSetup& setup);

}  // namespace rtsim
