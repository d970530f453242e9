#pragma once
// Bring your own rays: a trace folder from rays the caller gives (no camera, no secondaries),
// written through the same TraceFolderWriter as trace_scene, so the model replays it like any
// trace and checks every hit against the reference traversal.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "traces/accel/accel.h"
#include "traces/raygen/secondary.h"
#include "traces/scene/scene.h"
#include "traces/tracer/trace_folder.h"
#include "traces/tracer/tracer.h"

namespace rtsim {

struct RayTraceOptions {
    std::string out_dir;   ///< created if missing
    unsigned threads = 0;  ///< 0: all hardware threads. Output does not depend on it.
};

/// Traces `rays` in order (each with its kind, pixel, depth and any-hit flag) through `accel`,
/// a structure built over `scene`, and writes OUT/trace.rtt and OUT/manifest.json. Every ray is
/// written, whatever the scene calls for: the manifest's workload says they were given by the
/// caller, per kind. Throws rtsim::Error if there are no rays.
nlohmann::json write_ray_trace(const Scene& scene, const SceneLabel& label, const Accel& accel,
                               const std::vector<PendingRay>& rays, const RayTraceOptions& options,
                               const ProgressFn& progress = {});

}  // namespace rtsim
