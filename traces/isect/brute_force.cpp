// Brute force and the alpha test: the definitions the structures' traversals are checked against.
#include "traces/isect/brute_force.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "traces/common/rng.h"
#include "traces/isect/leaf_kernel.h"
#include "traces/isect/ray_triangle.h"

namespace rtsim {

Hit trace_ray_brute_force(const HwTriangle* triangles, size_t count, const Ray& ray, TraversalMode mode) {
    Hit best;
    if (!ray_is_valid(ray)) return best;
    const RayTrianglePre pre = ray_triangle_precompute(ray);
    best.t = ray.tmax;
    // Triangles in primitive-id order, whatever order the structure stores them in.
    uint32_t max_prim = 0;
    for (size_t i = 0; i < count; ++i) max_prim = std::max(max_prim, triangles[i].prim);
    std::vector<const HwTriangle*> order(count ? size_t(max_prim) + 1 : 0, nullptr);
    for (size_t i = 0; i < count; ++i) order[triangles[i].prim] = &triangles[i];
    // Each record by the hit rules every structure shares (leaf_kernel.h).
    float cull = detail::cull_distance(best.t);
    uint32_t alpha_tests = 0;
    for (const HwTriangle* tri : order) {
        if (!tri) continue;
        if (mode == TraversalMode::any_hit) {
            if (detail::triangle_step<true>(pre, ray.tmin, ray.tmax, *tri, best, cull, alpha_tests)) break;
        } else {
            detail::triangle_step<false>(pre, ray.tmin, ray.tmax, *tri, best, cull, alpha_tests);
        }
    }
    if (best.prim < 0) best = Hit{};
    return best;
}

bool alpha_test_accepts(uint32_t prim, float u, float v, uint32_t coverage_x255) {
    if (coverage_x255 >= 255) return true;
    if (coverage_x255 == 0) return false;
    // u, v quantised to 1/1024 so tiny arithmetic differences cannot flip the decision. A NaN or
    // far-out u, v (from a corrupt trace's triangle) is clamped first: converting it is undefined.
    const auto quantise = [](float x) {
        const float inside = std::isfinite(x) ? std::clamp(x, -4.0f, 4.0f) : 0.0f;
        return uint64_t(int64_t(std::floor(inside * 1024.0f)) & 0x7FF);
    };
    const uint64_t h = hash_combine(0xA1FAu, prim, quantise(u), quantise(v));
    return hash_to_unit(h) * 255.0f < float(coverage_x255);
}

}  // namespace rtsim
