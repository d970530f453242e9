#pragma once
// The trace file (docs/trace_format.md): versioned, sectioned, checksummed per chunk, written
// and read in streaming fashion. One file `trace.rtt` beside `manifest.json` in a trace folder.
//
//   [header 64 B][section payloads, each 64-byte aligned][per-chunk CRC32 tables][section table]
//
// Sections hold fixed-size records, contiguous, so a reader can memory-map one as an array.
// Every `chunk_bytes` of a section's payload carry a CRC32 (zlib polynomial).
#include <cstdint>
#include <string>

#include "traces/common/ray.h"
#include "traces/common/record_layout.h"
#include "traces/format/shading_format.h"

namespace rtsim {

constexpr char kTraceMagic[8] = {'R', 'T', 'S', 'I', 'M', 'T', 'R', 'C'};
/// 6: sphere tests in WORK records (curved primitives); 5: shading (MATL, TEXR, PTRI, SHAD, TXFT:
/// traces/format/shading_format.h); 4: animated frames (FRMS; a two-level image's TLAS per frame).
constexpr uint32_t kTraceVersion = 6;
/// Oldest version this build reads (versions 3 to 5 have WORK records without sphere_tests,
/// which the reader widens with a zero there; versions 3 and 4 have no shading sections and are
/// simulated without shading; version 3 has no frames; their layout is otherwise version 6's).
constexpr uint32_t kTraceVersionOldest = 3;
/// Bytes of a WORK record before version 6 (the traced fields before sphere_tests).
constexpr uint32_t kWorkRecordBytesV5 = 32;

/// Section kinds (fourcc, little-endian). Never renumber; add new kinds instead.
enum class SectionKind : uint32_t {
    rays = 0x53594152,       // 'RAYS': RayRecord
    hits = 0x53544948,       // 'HITS': HitRecord
    work = 0x4B524F57,       // 'WORK': WorkRecord
    accel = 0x4C434341,      // 'ACCL': the acceleration structure's descriptor, JSON text (1-byte records)
    frames = 0x534D5246,     // 'FRMS': FrameRecord, one per frame (animated traces only)
    materials = 0x4C54414D,  // 'MATL': MaterialRecord (version 5)
    textures = 0x52584554,   // 'TEXR': TextureRecord (version 5; absent when no material has a texture)
    tri_shading = 0x49525450,  // 'PTRI': TriShadeRecord, one per primitive (version 5)
    shading = 0x44414853,    // 'SHAD': ShadeRecord, one per ray (version 5)
    texel_fetches = 0x54465854,  // 'TXFT': uint64 texel addresses (version 5)
    // 'RG00'..'RG99': region i of the acceleration-structure image (record size: its descriptor)
};
/// The section holding region `index` (0..99) of the acceleration-structure image.
SectionKind region_section(uint32_t index);
/// True for a region section ('RG00'..'RG99'); *index gets its region index.
bool is_region_section(SectionKind kind, uint32_t* index = nullptr);
/// "RAYS", "HITS", ..., "RG03"; "unknown" for a kind this build does not know.
std::string section_name(SectionKind kind);
/// Record size a kind must have (RAYS 40, HITS 20, WORK 36 (32 before version 6), ACCL 1, FRMS 16, MATL 32, TEXR 32, PTRI 44,
/// SHAD 32, TXFT 8); 0 if it varies (regions)
/// or the kind is unknown.
uint32_t section_record_bytes(SectionKind kind);
/// Regions an image may have (the region sections' two digits).
constexpr uint32_t kMaxRegionSections = 100;

#pragma pack(push, 1)
/// One ray of the trace (40 bytes).
struct RayRecord {
    float origin[3];      //  0
    float tmin;           // 12
    float direction[3];   // 16
    float tmax;           // 28
    uint32_t pixel;       // 32: y * width + x of the camera pixel the ray descends from
    uint8_t kind;         // 36: RayKind
    uint8_t flags;        // 37: bit 0: any-hit (occlusion) ray
    uint16_t depth;       // 38: 0 for primary rays, +1 per bounce
};
/// Reference hit of the ray at the same index (20 bytes).
struct HitRecord {
    int32_t prim;         //  0: -1 for a miss
    int32_t inst;         //  4
    float t;              //  8: +inf for a miss
    float u;              // 12
    float v;              // 16
};
/// Work the reference traversal did for the ray at the same index: WorkCounts' traced fields (4
/// bytes per field of RTSIM_WORK_FIELDS in traces/common/work_counts.h, in order, no padding).
struct WorkRecord {
#define RTSIM_WORK_MEMBER(name, tests_of, plan_step, doc) uint32_t name = 0;
    RTSIM_WORK_FIELDS(RTSIM_WORK_MEMBER)
#undef RTSIM_WORK_MEMBER

    /// The record of `w` (which must have no mailbox counts: a trace's work has none).
    static WorkRecord of(const WorkCounts& w) {
        WorkRecord r;
#define RTSIM_WORK_COPY(name, tests_of, plan_step, doc) r.name = w.name;
        RTSIM_WORK_FIELDS(RTSIM_WORK_COPY)
#undef RTSIM_WORK_COPY
        return r;
    }
    /// The counts this record holds (the model's own counts zero).
    WorkCounts counts() const {
        WorkCounts w;
#define RTSIM_WORK_COPY(name, tests_of, plan_step, doc) w.name = name;
        RTSIM_WORK_FIELDS(RTSIM_WORK_COPY)
#undef RTSIM_WORK_COPY
        return w;
    }
};
/// One frame of an animated trace (16 bytes): its rays are RAYS[first_ray, first_ray + rays),
/// traced against the structure's frame of the same index (Accel::bind_frame).
struct FrameRecord {
    uint64_t first_ray;    //  0
    uint64_t rays;         //  8
};
#pragma pack(pop)
static_assert(sizeof(FrameRecord) == 16, "FrameRecord layout");
static_assert(sizeof(RayRecord) == 40, "RayRecord layout");
static_assert(sizeof(HitRecord) == 20, "HitRecord layout");
static_assert(sizeof(WorkRecord) == kTracedWorkFieldCount * sizeof(uint32_t), "WorkRecord layout");

/// The records' layouts (numpy reads the sections with them: python/rtsim/trace_file.py).
inline RecordLayout layout_of(const RayRecord*) {
    return {RTSIM_FIELD(RayRecord, origin), RTSIM_FIELD(RayRecord, tmin),  RTSIM_FIELD(RayRecord, direction),
            RTSIM_FIELD(RayRecord, tmax),   RTSIM_FIELD(RayRecord, pixel), RTSIM_FIELD(RayRecord, kind),
            RTSIM_FIELD(RayRecord, flags),  RTSIM_FIELD(RayRecord, depth)};
}
inline RecordLayout layout_of(const HitRecord*) {
    return {RTSIM_FIELD(HitRecord, prim), RTSIM_FIELD(HitRecord, inst), RTSIM_FIELD(HitRecord, t),
            RTSIM_FIELD(HitRecord, u),    RTSIM_FIELD(HitRecord, v)};
}
inline RecordLayout layout_of(const WorkRecord*) {
    return {
#define RTSIM_WORK_LAYOUT(name, tests_of, plan_step, doc) RTSIM_FIELD(WorkRecord, name),
        RTSIM_WORK_FIELDS(RTSIM_WORK_LAYOUT)
#undef RTSIM_WORK_LAYOUT
    };
}
inline RecordLayout layout_of(const FrameRecord*) {
    return {RTSIM_FIELD(FrameRecord, first_ray), RTSIM_FIELD(FrameRecord, rays)};
}

constexpr uint8_t kRayFlagAnyHit = 1u << 0;

/// Conversions between the tracer's types and the records.
RayRecord to_record(const Ray& ray, RayKind kind, uint32_t pixel, uint16_t depth, bool any_hit);
Ray ray_from_record(const RayRecord& r);
HitRecord to_record(const Hit& hit);
Hit hit_from_record(const HitRecord& h);

}  // namespace rtsim
