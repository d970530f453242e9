#pragma once
// Traces a wavefront of rays on all threads. Results land at the ray's index, so the output is
// identical whatever the thread count.
#include <cstdint>
#include <functional>
#include <vector>

#include "traces/accel/accel.h"
#include "traces/raygen/secondary.h"

namespace rtsim {

struct WavefrontResult {
    std::vector<Hit> hits;
    std::vector<WorkCounts> work;
    uint64_t rejected = 0;  ///< rays failing ray_is_valid (never traversed)
};

/// progress(done) is called from the calling thread only.
/// `step`: what the rays walk with (the any-hit order of the trace; nothing else changes a
/// reference walk).
WavefrontResult trace_wavefront(const Accel& accel, const std::vector<PendingRay>& rays, unsigned threads,
                                const std::function<void(uint64_t)>& progress, const StepOptions& step = {});

}  // namespace rtsim
