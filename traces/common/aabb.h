#pragma once
// Axis-aligned bounding box in float, the unit of every BVH node.
#include <algorithm>
#include <limits>

#include <glm/glm.hpp>

namespace rtsim {

using Vec3 = glm::vec3;

struct Aabb {
    Vec3 lo{std::numeric_limits<float>::infinity()};
    Vec3 hi{-std::numeric_limits<float>::infinity()};

    void grow(const Vec3& p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    void grow(const Aabb& b) {
        lo = glm::min(lo, b.lo);
        hi = glm::max(hi, b.hi);
    }
    bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
    Vec3 center() const { return (lo + hi) * 0.5f; }
    Vec3 extent() const { return hi - lo; }
    /// Half the surface area: the SAH only needs ratios, so the factor 2 is dropped.
    float half_area() const {
        if (empty()) return 0.0f;
        Vec3 e = extent();
        return e.x * e.y + e.y * e.z + e.z * e.x;
    }
    int largest_axis() const {
        Vec3 e = extent();
        return (e.x >= e.y && e.x >= e.z) ? 0 : (e.y >= e.z ? 1 : 2);
    }
    bool contains(const Aabb& b) const {
        return b.empty() || (lo.x <= b.lo.x && lo.y <= b.lo.y && lo.z <= b.lo.z && hi.x >= b.hi.x &&
                             hi.y >= b.hi.y && hi.z >= b.hi.z);
    }
};

}  // namespace rtsim
