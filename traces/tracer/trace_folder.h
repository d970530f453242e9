#pragma once
// The write side of a trace folder, shared by every producer of traces (trace_scene for a
// scene's workload, write_ray_trace for rays a user brings), so a change to the trace format
// or to the manifest's common keys lands here once:
//   OUT/trace.rtt      the acceleration-structure image, then each traced wavefront's rays,
//                      reference hits and work
//   OUT/manifest.json  format and versions, scene, structure, counts, files, timing + the
//                      producer's keys
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "traces/accel/accel_image.h"
#include "traces/format/trace_writer.h"
#include "traces/raygen/workload.h"
#include "traces/scene/scene.h"
#include "traces/shading/materials.h"
#include "traces/tracer/manifest.h"
#include "traces/tracer/wavefront.h"

namespace rtsim {

/// How the scene is named in the manifest: procedural scenes by name, files by their stem.
struct SceneLabel {
    std::string name;
    bool procedural = false;
};

class TraceFolderWriter {
public:
    /// Creates OUT and starts OUT/trace.rtt with the structure's image (traces/accel/accel_io.h).
    TraceFolderWriter(const std::string& out_dir, const AccelImage& image);

    /// Writes the shading sections (materials, textures, per-primitive attributes) and, from
    /// here on, each written ray's shading record and texel addresses (traces/shading). Without
    /// a call the trace has no shading sections. `scene` must outlive the writer.
    void set_shading(const Scene& scene, ShadingScene shading);

    /// Appends the rays of a traced wavefront that the plan wants, in order, with their hits and
    /// work; every ray is counted in the manifest's per-kind statistics (written or not).
    void add_wavefront(const WorkloadPlan& plan, const std::vector<PendingRay>& rays,
                       const WavefrontResult& result);

    /// Rays written so far (the next ray's index in the trace).
    uint64_t rays_written() const { return m_rays_written; }
    /// Animated traces: a FRMS record for the frame whose rays are [first_ray, rays_written()).
    void add_frame(uint64_t first_ray);

    /// Closes trace.rtt, then writes manifest.json: the common keys plus `extra` (the producer's
    /// "camera", "workload", ...; `files` entries in extra are added to the common ones).
    /// Timing: `load_ms` is the producer's scene loading, `started` when the producer began.
    /// Returns the manifest.
    nlohmann::json finish(const Scene& scene, const SceneLabel& label, const AccelImage& image,
                          double load_ms, std::chrono::steady_clock::time_point started,
                          nlohmann::json extra);

    const std::string& out_dir() const { return m_out_dir; }

private:
    ShadeRecord shade_record(const PendingRay& r, const Hit& hit, std::vector<uint64_t>* fetches);

    std::string m_out_dir;
    TraceWriter m_writer;
    RayCounts m_counts;
    uint64_t m_rays_written = 0;
    const Scene* m_scene = nullptr;  ///< set by set_shading
    ShadingScene m_shading;
    std::vector<TriShadeRecord> m_tri;
    std::vector<int64_t> m_wave_index;  ///< previous wavefront: position -> trace index (-1 unwritten)
    uint64_t m_fetches = 0;             ///< texel addresses written so far
    std::chrono::steady_clock::time_point m_start;
};

}  // namespace rtsim
