#pragma once
// The instance record of a two-level structure (docs/accel.md, "Two-level structures"): where a
// TLAS leaf points. 128 bytes, two cache lines; the transform step fetches the first line only
// (what traversal needs), the second holds the object-to-world matrix for shading and tools.
#include "traces/common/record_layout.h"
#include <cstdint>

#include <glm/glm.hpp>

#include "traces/common/ray.h"

namespace rtsim {

struct InstanceRecord {             // 128 bytes
    float world_to_object[12];      //   0: rows 0..2 of the 3x4 inverse transform, row-major
    uint32_t blas;                  //  48: bottom-level structure (index into the BLAS list)
    uint32_t prim_base;             //  52: primitive id of the mesh's triangle 0 in this instance
    uint32_t instance;              //  56: instance id (scene order, scene.h)
    uint32_t reserved0;             //  60: 0
    float object_to_world[12];      //  64: rows 0..2 of the 3x4 transform, row-major
    uint32_t reserved1[4];          // 112: 0
};
static_assert(sizeof(InstanceRecord) == 128, "InstanceRecord must be 128 bytes");
inline RecordLayout layout_of(const InstanceRecord*) {
    return {RTSIM_FIELD(InstanceRecord, world_to_object), RTSIM_FIELD(InstanceRecord, blas),
            RTSIM_FIELD(InstanceRecord, prim_base),       RTSIM_FIELD(InstanceRecord, instance),
            RTSIM_FIELD(InstanceRecord, reserved0),       RTSIM_FIELD(InstanceRecord, object_to_world),
            RTSIM_FIELD(InstanceRecord, reserved1)};
}

/// Where the instance records live: the array and its address in the memory image.
struct InstanceRecordView {
    const InstanceRecord* records = nullptr;
    uint64_t count = 0;
    uint64_t base = 0;  ///< address of record 0
};

/// Bytes a transform step fetches: the first line (inverse transform and ids).
constexpr uint32_t kInstanceFetchBytes = 64;

/// Rows 0..2 of a 4x4 affine matrix (glm is column-major), each entry rounded once to float.
inline void store_affine_rows(const glm::dmat4& m, float out[12]) {
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) out[r * 4 + c] = float(m[c][r]);
}

/// The ray in an instance's object space: origin and direction through the stored inverse,
/// each component a dot product evaluated in double and rounded once to float. The direction is
/// not renormalised, so the ray parameter t is the same in both spaces (hits report world t).
inline Ray transform_ray(const float w2o[12], const Ray& ray) {
    Ray out = ray;
    for (int r = 0; r < 3; ++r) {
        const float* m = w2o + r * 4;
        out.origin[r] = float(double(m[0]) * ray.origin.x + double(m[1]) * ray.origin.y +
                              double(m[2]) * ray.origin.z + double(m[3]));
        out.direction[r] = float(double(m[0]) * ray.direction.x + double(m[1]) * ray.direction.y +
                                 double(m[2]) * ray.direction.z);
    }
    return out;
}

}  // namespace rtsim
