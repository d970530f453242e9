#pragma once
// What each fidelity level can cost (docs/fidelity.md), as data: the resolution step matches a
// unit kind's and the techniques' needs against it. The analytic level is two levels here: its
// statistical caches price steps from the trace's work records, its functional caches step
// every ray (analytic.caches).
#include <string>

#include "sim/config/config.h"

namespace rtsim {

struct LevelCapabilities {
    std::string name;        ///< "approx", "analytic (analytic.caches=statistical)", ...
    bool timed = false;      ///< the SystemC model times it (approx, detailed)
    bool lock_step = false;  ///< it times groups of rays stepping in lock-step (warps, packets)
    /// It costs lock-step groups from the unit kind's functional group profile
    /// (UnitKind::group_profile) where the kind has one.
    bool group_profiles = false;
    bool treelets = false;   ///< it models treelet admission and queues
    bool frames = false;     ///< it replays an animated trace's frames
    /// It steps every ray itself. A level that does not (the statistical analytic level) still
    /// counts the work the trace's records hold none of (mailbox lookups, restart-trail
    /// restarts, a reduced-precision walk's extra steps): measured on its stepped sample and
    /// scaled to the trace (sim/analytic/analytic.cpp), so no technique needs this.
    bool steps_rays = false;
    bool shades = false;     ///< it times the frame: shading and the frame loop (approx, detailed)
};

/// The capabilities of the level `config` runs at.
LevelCapabilities level_capabilities(const SimConfig& config);

}  // namespace rtsim
