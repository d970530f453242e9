// Section names and sizes, and conversions between the tracer's types and the trace records.
#include "traces/format/trace_format.h"

#include "traces/bvh/hw_layout.h"

namespace rtsim {

const char* section_name(SectionKind kind) {
    switch (kind) {
    case SectionKind::rays: return "RAYS";
    case SectionKind::hits: return "HITS";
    case SectionKind::work: return "WORK";
    case SectionKind::bvh_nodes: return "NODE";
    case SectionKind::triangles: return "TRIS";
    }
    return "unknown";
}

uint32_t section_record_bytes(SectionKind kind) {
    switch (kind) {
    case SectionKind::rays: return sizeof(RayRecord);
    case SectionKind::hits: return sizeof(HitRecord);
    case SectionKind::work: return sizeof(WorkRecord);
    case SectionKind::bvh_nodes: return sizeof(HwNode);
    case SectionKind::triangles: return sizeof(HwTriangle);
    }
    return 0;
}

RayRecord to_record(const Ray& ray, RayKind kind, uint32_t pixel, uint16_t depth, bool any_hit) {
    RayRecord r{};
    for (int i = 0; i < 3; ++i) {
        r.origin[i] = ray.origin[i];
        r.direction[i] = ray.direction[i];
    }
    r.tmin = ray.tmin;
    r.tmax = ray.tmax;
    r.pixel = pixel;
    r.kind = static_cast<uint8_t>(kind);
    r.flags = any_hit ? kRayFlagAnyHit : 0;
    r.depth = depth;
    return r;
}

Ray ray_from_record(const RayRecord& r) {
    Ray ray;
    ray.origin = Vec3(r.origin[0], r.origin[1], r.origin[2]);
    ray.direction = Vec3(r.direction[0], r.direction[1], r.direction[2]);
    ray.tmin = r.tmin;
    ray.tmax = r.tmax;
    return ray;
}

HitRecord to_record(const Hit& hit) { return HitRecord{hit.prim, hit.inst, hit.t, hit.u, hit.v}; }

Hit hit_from_record(const HitRecord& h) {
    Hit hit;
    hit.prim = h.prim;
    hit.inst = h.inst;
    hit.t = h.t;
    hit.u = h.u;
    hit.v = h.v;
    return hit;
}

WorkRecord to_record(const WorkCounts& w) {
    return WorkRecord{w.nodes, w.box_tests, w.tri_tests, w.anyhit_calls, w.transforms};
}

WorkCounts work_from_record(const WorkRecord& w) {
    WorkCounts c;
    c.nodes = w.nodes;
    c.box_tests = w.box_tests;
    c.tri_tests = w.tri_tests;
    c.anyhit_calls = w.anyhit_calls;
    c.transforms = w.transforms;
    return c;
}

}  // namespace rtsim
