#pragma once
// Robust ray/box slab test (Ize 2013, "Robust BVH Ray Traversal"): reciprocal directions with
// signed infinities for ±0 components, far distance scaled by 1 + 2*gamma(3) so no box a ray
// truly crosses is missed to rounding; NaN from 0 * inf never decides the outcome.
#include "traces/bvh/hw_layout.h"
#include "traces/common/ray.h"

namespace rtsim {

struct RayBoxPre {
    Vec3 origin;
    Vec3 inv_dir;  ///< 1 / direction, ±inf for ±0 (sign bit kept)
    /// The same two vectors padded to 4 lanes (lane 3 = 0) for the SIMD node test.
    alignas(16) float origin4[4];
    alignas(16) float inv_dir4[4];
    /// For the SIMD node test: (ox, ox, oy, oy), (1/dx, 1/dx, 1/dy, 1/dy) and z in all lanes.
    alignas(16) float origin_xy[4];
    alignas(16) float inv_dir_xy[4];
    alignas(16) float origin_z[4];   ///< oz in every lane
    alignas(16) float inv_dir_z[4];  ///< 1/dz in every lane
    /// Byte offsets from HwNode::bounds of both children's near and far planes per axis:
    /// axis a at 16 * a, the max plane (+8) is near where inv_dir is negative (sign bit set).
    uint32_t near_offset[3];
    uint32_t far_offset[3];
};

RayBoxPre ray_box_precompute(const Ray& ray);

/// Tests both child boxes of a node against [tmin, tmax]. Returns a 2-bit mask of children hit;
/// tnear[i] is the entry distance of child i (valid where its bit is set).
unsigned intersect_node_boxes(const RayBoxPre& pre, const HwNode& node, float tmin, float tmax,
                              float tnear[2]);

/// One box, same arithmetic. Returns true and the entry distance if hit.
bool intersect_box(const RayBoxPre& pre, const float lo[3], const float hi[3], float tmin,
                   float tmax, float* tnear);

}  // namespace rtsim
