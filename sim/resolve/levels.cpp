#include "sim/resolve/levels.h"

namespace rtsim {

LevelCapabilities level_capabilities(const SimConfig& c) {
    LevelCapabilities l;
    l.name = kFidelityChoices.name(c.fidelity);
    switch (c.fidelity) {
        case Fidelity::functional:
            // The reference walks, no time: every kind's rays walk as they would (packets as
            // packets), and the timing-only techniques have nothing to change.
            l.lock_step = l.treelets = l.frames = l.steps_rays = true;
            break;
        case Fidelity::analytic: {
            // A closed form over a per-trace analysis: plain dispatch; a lock-step kind's
            // groups from its functional group profile (sim/analytic/estimate.cpp).
            const bool functional = c.analytic.caches == AnalyticCaches::functional;
            l.group_profiles = !functional;
            // Its sample stepped in treelet order, the ray buffer's traffic priced (sample.h).
            l.treelets = !functional;
            // Animated traces: the analysis's clusters frame by frame, the estimate shared out by
            // frame with each barrier and build (sim/harness/analytic_frames.h).
            l.frames = !functional;
            l.name += std::string(" (analytic.caches=") + (functional ? "functional" : "statistical") + ")";
            l.steps_rays = functional;
            break;
        }
        case Fidelity::approx:
        case Fidelity::detailed:
            l.timed = l.lock_step = l.treelets = l.frames = l.steps_rays = l.shades = true;
            break;
    }
    return l;
}

}  // namespace rtsim
