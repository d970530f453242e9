// Public entry points of the robust ray/box test; the arithmetic is in ray_box_kernel.h.
#include "traces/isect/ray_box.h"

#include <cmath>

#include "traces/isect/ray_box_kernel.h"

namespace rtsim {

RayBoxPre ray_box_precompute(const Ray& ray) {
    RayBoxPre pre;
    pre.origin = ray.origin;
    // IEEE division: 1 / +0 = +inf and 1 / -0 = -inf, so the sign of a zero component survives.
    pre.inv_dir = Vec3(1.0f / ray.direction.x, 1.0f / ray.direction.y, 1.0f / ray.direction.z);
    for (int a = 0; a < 3; ++a) {
        pre.origin4[a] = pre.origin[a];
        pre.inv_dir4[a] = pre.inv_dir[a];
    }
    pre.origin4[3] = 0.0f;
    pre.inv_dir4[3] = 0.0f;
    for (int lane = 0; lane < 4; ++lane) {
        pre.origin_xy[lane] = pre.origin[lane / 2];
        pre.inv_dir_xy[lane] = pre.inv_dir[lane / 2];
        pre.origin_z[lane] = pre.origin.z;
        pre.inv_dir_z[lane] = pre.inv_dir.z;
    }
    for (int a = 0; a < 3; ++a) {
        const uint32_t near_max = std::signbit(pre.inv_dir[a]) ? 1u : 0u;
        pre.near_offset[a] = 16u * uint32_t(a) + 8u * near_max;
        pre.far_offset[a] = 16u * uint32_t(a) + 8u * (1u - near_max);
    }
    return pre;
}

unsigned intersect_node_boxes(const RayBoxPre& pre, const HwNode& node, float tmin, float tmax,
                              float tnear[2]) {
    return detail::node_kernel(pre, node, tmin, tmax, tnear);
}

bool intersect_box(const RayBoxPre& pre, const float lo[3], const float hi[3], float tmin,
                   float tmax, float* tnear) {
    return detail::box_kernel(pre, lo, hi, tmin, tmax, tnear);
}

}  // namespace rtsim
