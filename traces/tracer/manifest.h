#pragma once
// Pieces of the trace manifest (manifest.json), documented in docs/trace_format.md.
#include <nlohmann/json.hpp>

#include "traces/accel/accel_image.h"
#include "traces/raygen/workload.h"
#include "traces/scene/scene.h"

namespace rtsim {

nlohmann::json scene_json(const Scene& scene, const std::string& name, bool procedural);
/// The structure's kind, build statistics, footprint and regions (manifest "accel").
nlohmann::json accel_json(const AccelImage& image);
nlohmann::json camera_json(const Camera& camera, const std::string& source);
nlohmann::json effects_json(const WorkloadPlan& plan);

/// Per-kind ray statistics, accumulated wavefront by wavefront.
class RayCounts {
public:
    void add(RayKind kind, uint16_t depth, const Hit& hit, const WorkCounts& work, bool written);
    void add_rejected(uint64_t n) { m_rejected += n; }
    uint64_t written() const { return m_written; }
    nlohmann::json to_json() const;

private:
    struct KindStats {
        uint64_t rays = 0, hits = 0, written = 0, steps = 0, box_tests = 0, tri_tests = 0, sphere_tests = 0, capsule_tests = 0,
                 anyhit_calls = 0;
        uint16_t max_depth = 0;
    };
    KindStats m_kinds[kRayKindCount];
    uint64_t m_written = 0;
    uint64_t m_rejected = 0;
};

}  // namespace rtsim
