#pragma once
// Brute-force closest or any hit over a triangle array, with the arithmetic and tie rules every
// structure uses (leaf_kernel.h): the reference the structures are tested against.
#include <cstddef>

#include "traces/common/hw_triangle.h"
#include "traces/common/ray.h"

namespace rtsim {

/// Tests every triangle in primitive-id order, whatever order they are stored in; duplicated
/// references to one primitive (spatial splits) are tested once.
Hit trace_ray_brute_force(const HwTriangle* triangles, size_t count, const Ray& ray, TraversalMode mode);

}  // namespace rtsim
