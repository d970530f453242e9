// Section names and sizes, and conversions between the tracer's types and the trace records.
#include "traces/format/trace_format.h"

namespace rtsim {

SectionKind region_section(uint32_t index) {
    const uint32_t tens = '0' + index / 10 % 10, ones = '0' + index % 10;
    return static_cast<SectionKind>(uint32_t('R') | uint32_t('G') << 8 | tens << 16 | ones << 24);
}

bool is_region_section(SectionKind kind, uint32_t* index) {
    const auto v = static_cast<uint32_t>(kind);
    const uint32_t tens = (v >> 16) & 0xFF, ones = v >> 24;
    if ((v & 0xFFFF) != (uint32_t('R') | uint32_t('G') << 8) || tens < '0' || tens > '9' || ones < '0' || ones > '9')
        return false;
    if (index) *index = (tens - '0') * 10 + (ones - '0');
    return true;
}

std::string section_name(SectionKind kind) {
    switch (kind) {
    case SectionKind::rays: return "RAYS";
    case SectionKind::hits: return "HITS";
    case SectionKind::work: return "WORK";
    case SectionKind::accel: return "ACCL";
    case SectionKind::frames: return "FRMS";
    case SectionKind::materials: return "MATL";
    case SectionKind::textures: return "TEXR";
    case SectionKind::tri_shading: return "PTRI";
    case SectionKind::shading: return "SHAD";
    case SectionKind::texel_fetches: return "TXFT";
    }
    uint32_t index;
    if (is_region_section(kind, &index)) return "RG" + std::to_string(index / 10) + std::to_string(index % 10);
    return "unknown";
}

uint32_t section_record_bytes(SectionKind kind) {
    switch (kind) {
    case SectionKind::rays: return sizeof(RayRecord);
    case SectionKind::hits: return sizeof(HitRecord);
    case SectionKind::work: return sizeof(WorkRecord);
    case SectionKind::accel: return 1;
    case SectionKind::frames: return sizeof(FrameRecord);
    case SectionKind::materials: return sizeof(MaterialRecord);
    case SectionKind::textures: return sizeof(TextureRecord);
    case SectionKind::tri_shading: return sizeof(TriShadeRecord);
    case SectionKind::shading: return sizeof(ShadeRecord);
    case SectionKind::texel_fetches: return sizeof(uint64_t);
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

}  // namespace rtsim
