#pragma once
// The hardware triangle record every acceleration structure's leaves reference (48 bytes,
// docs/bvh_layout.md): the one triangle layout the reference tracer and the model both read.
#include <cstdint>

#include "traces/common/record_layout.h"

namespace rtsim {

/// HwTriangle::flags bits.
constexpr uint32_t kTriAnyHit = 1u << 0;         ///< alpha-MASK: call the any-hit (alpha) test
/// The record is a sphere (docs/bvh_layout.md, "Sphere records"): v0 its centre, v1[0] its
/// radius, v1[1..2] and v2 zero.
constexpr uint32_t kPrimSphere = 1u << 1;
/// The record is a capsule (docs/bvh_layout.md, "Capsule records"): a sphere swept from v0 to
/// v1, its radius going from v2[0] at v0 to v2[1] at v1; v2[2] zero.
constexpr uint32_t kPrimCapsule = 1u << 2;
constexpr uint32_t kTriCoverageShift = 8;        ///< bits 8..15: alpha coverage x 255
constexpr uint32_t kTriMaterialShift = 16;       ///< bits 16..31: material index

struct HwTriangle {             // 48 bytes
    float v0[3];                //  0
    float v1[3];                // 12
    float v2[3];                // 24
    uint32_t prim;              // 36: stable primitive id (scene order, see scene.h)
    uint32_t inst;              // 40: instance id
    uint32_t flags;             // 44: kTriAnyHit | kPrimSphere | kPrimCapsule | coverage << 8 | material << 16
};
static_assert(sizeof(HwTriangle) == 48, "HwTriangle must be 48 bytes");
inline bool is_sphere(const HwTriangle& t) { return (t.flags & kPrimSphere) != 0; }
inline bool is_capsule(const HwTriangle& t) { return (t.flags & kPrimCapsule) != 0; }
/// A curved primitive (sphere or capsule): tested by its own pipeline, not the triangle's.
inline bool is_curved(const HwTriangle& t) { return (t.flags & (kPrimSphere | kPrimCapsule)) != 0; }
inline RecordLayout layout_of(const HwTriangle*) {
    return {RTSIM_FIELD(HwTriangle, v0),   RTSIM_FIELD(HwTriangle, v1),   RTSIM_FIELD(HwTriangle, v2),
            RTSIM_FIELD(HwTriangle, prim), RTSIM_FIELD(HwTriangle, inst), RTSIM_FIELD(HwTriangle, flags)};
}

}  // namespace rtsim
