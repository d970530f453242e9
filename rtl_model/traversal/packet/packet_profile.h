#pragma once
// The packet kind's packets walked functionally, for the analytic level (unit_kind.h,
// GroupProfile): each unit's rays grouped traversal.packet.lanes at a time as dispatch deals them and traced
// through the structure's reference packet loop (the walk the model's packet unit takes, the one
// its hit checker checks against), beside the same rays walked alone.
#include <vector>

#include "rtl_model/traversal/unit_kind.h"

namespace rtsim {

GroupProfile packet_group_profile(const Accel& accel, const StepOptions& step, const TraversalConfig& traversal,
                                  const std::vector<std::vector<RayJob>>& rays_by_unit, const GroupSetup& setup);

}  // namespace rtsim
