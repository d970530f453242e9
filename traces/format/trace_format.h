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

namespace rtsim {

constexpr char kTraceMagic[8] = {'R', 'T', 'S', 'I', 'M', 'T', 'R', 'C'};
constexpr uint32_t kTraceVersion = 2;  // 2: HwNode boxes in the per-axis bounds layout

/// Section kinds (fourcc, little-endian). Never renumber; add new kinds instead.
enum class SectionKind : uint32_t {
    rays = 0x53594152,       // 'RAYS': RayRecord
    hits = 0x53544948,       // 'HITS': HitRecord
    work = 0x4B524F57,       // 'WORK': WorkRecord
    bvh_nodes = 0x45444F4E,  // 'NODE': HwNode (64 B)
    triangles = 0x53495254,  // 'TRIS': HwTriangle (48 B)
};
/// "RAYS", "HITS", ...; "unknown" for a kind this build does not know.
const char* section_name(SectionKind kind);
/// Record size a kind must have (RAYS 40, HITS 20, WORK 20, NODE 64, TRIS 48); 0 if unknown.
uint32_t section_record_bytes(SectionKind kind);

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
/// Work the reference traversal did for the ray at the same index (20 bytes).
struct WorkRecord {
    uint32_t nodes;        //  0
    uint32_t box_tests;    //  4
    uint32_t tri_tests;    //  8
    uint32_t anyhit_calls; // 12
    uint32_t transforms;   // 16
};
#pragma pack(pop)
static_assert(sizeof(RayRecord) == 40, "RayRecord layout");
static_assert(sizeof(HitRecord) == 20, "HitRecord layout");
static_assert(sizeof(WorkRecord) == 20, "WorkRecord layout");

constexpr uint8_t kRayFlagAnyHit = 1u << 0;

/// Conversions between the tracer's types and the records.
RayRecord to_record(const Ray& ray, RayKind kind, uint32_t pixel, uint16_t depth, bool any_hit);
Ray ray_from_record(const RayRecord& r);
HitRecord to_record(const Hit& hit);
Hit hit_from_record(const HitRecord& h);
WorkRecord to_record(const WorkCounts& w);
WorkCounts work_from_record(const WorkRecord& w);

}  // namespace rtsim
