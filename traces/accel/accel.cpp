#include "traces/accel/accel.h"

#include "traces/common/error.h"
#include "traces/common/hw_triangle.h"

namespace rtsim {

Hit Accel::trace(const Ray& ray, TraversalMode mode, WorkCounts* work, const StepOptions& options) const {
    std::unique_ptr<Stepper> s = make_stepper(options);
    return trace_with_stepper(*s, ray, mode, work);
}

void Accel::trace_packet(const Ray* rays, const TraversalMode* modes, uint32_t n, Hit* hits, WorkCounts* work,
                         PacketCounts* counts, float split_below, const StepOptions& options) const {
    const std::unique_ptr<PacketStepper> s = make_packet_stepper(options);
    require(s != nullptr, "structure '" + kind() + "' has no packet traversal");
    s->set_split_below(split_below);
    s->begin_packet(rays, modes, n);
    while (!s->done()) s->execute();
    for (uint32_t i = 0; i < n; ++i) {
        if (hits) hits[i] = s->lane_hit(i);
        if (work) work[i] = s->lane_work(i);
    }
    if (counts) *counts = s->counts();
}

bool Accel::has_anyhit_triangles() const { return has_flagged_records(kTriAnyHit); }
bool Accel::has_spheres() const { return has_flagged_records(kPrimSphere); }
bool Accel::has_capsules() const { return has_flagged_records(kPrimCapsule); }
bool Accel::has_curved() const { return has_flagged_records(kPrimSphere | kPrimCapsule); }

std::vector<OpKind> Accel::with_record_kinds(std::vector<OpKind> kinds) const {
    if (has_anyhit_triangles()) kinds.push_back(OpKind::anyhit);
    if (has_spheres()) kinds.push_back(OpKind::sphere);
    if (has_capsules()) kinds.push_back(OpKind::capsule);
    return kinds;
}

bool Accel::has_flagged_records(uint32_t flag) const {
    for (const Region& r : m_image.regions) {
        if (r.kind != DataKind::triangle) continue;
        if (r.name.rfind("blas_", 0) == 0) continue;  // two levels: each BLAS reads its own
        const bool blocks = r.name == kLeafBlocksRegion;  // compressed: read the decoded triangles
        const HwTriangle* t = blocks ? m_triangles.triangles() : r.records<HwTriangle>();
        const uint64_t n = blocks ? m_triangles.count() : r.count;
        for (uint64_t i = 0; i < n; ++i)
            if (t[i].flags & flag) return true;
    }
    return false;
}

AccelCapabilities Accel::capabilities() const { return accel_capabilities(kind()); }

void Accel::bind_frame(uint32_t f) {
    require(f < frame_count(), "accel image '" + kind() + "': frame " + std::to_string(f) + " of " +
                                   std::to_string(frame_count()));
}

}  // namespace rtsim
