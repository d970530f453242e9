// Public entry points of the watertight ray/triangle test (Woop, Benthin & Wald 2013); the
// arithmetic is in ray_triangle_kernel.h.
#include "traces/isect/ray_triangle.h"

#include "traces/isect/ray_triangle_kernel.h"

#include <cmath>
#include <utility>

namespace rtsim {

RayTrianglePre ray_triangle_precompute(const Ray& ray) {
    RayTrianglePre pre;
    const Vec3& d = ray.direction;
    // kz: dimension where |dir| is largest (ties go to the lower axis, x before y before z).
    const float ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    pre.kz = (ax >= ay && ax >= az) ? 0 : (ay >= az ? 1 : 2);
    pre.kx = pre.kz + 1 == 3 ? 0 : pre.kz + 1;
    pre.ky = pre.kx + 1 == 3 ? 0 : pre.kx + 1;
    // Swap kx and ky to preserve the winding of triangles (so U, V, W keep their meaning).
    if (d[pre.kz] < 0.0f) std::swap(pre.kx, pre.ky);
    // Shear constants.
    pre.sx = d[pre.kx] / d[pre.kz];
    pre.sy = d[pre.ky] / d[pre.kz];
    pre.sz = 1.0f / d[pre.kz];
    pre.origin = ray.origin;
    pre.direction = ray.direction;
    return pre;
}

namespace detail {

bool is_degenerate(const float v0[3], const float v1[3], const float v2[3]) {
    const double e1[3] = {double(v1[0]) - v0[0], double(v1[1]) - v0[1], double(v1[2]) - v0[2]};
    const double e2[3] = {double(v2[0]) - v0[0], double(v2[1]) - v0[1], double(v2[2]) - v0[2]};
    const double nx = e1[1] * e2[2] - e1[2] * e2[1];
    const double ny = e1[2] * e2[0] - e1[0] * e2[2];
    const double nz = e1[0] * e2[1] - e1[1] * e2[0];
    return nx == 0.0 && ny == 0.0 && nz == 0.0;
}

}  // namespace detail

bool intersect_triangle(const RayTrianglePre& pre, const float v0[3], const float v1[3],
                        const float v2[3], float tmin, float tmax, TriangleHit* hit) {
    return detail::triangle_kernel(pre, v0, v1, v2, tmin, tmax, hit);
}

}  // namespace rtsim
