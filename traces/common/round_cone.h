// The one test of whether a round cone (a capsule of two radii) is a single sphere: the kernel,
// the surface point, the area and emissive sampling all take that case from here.
#pragma once

#include <cmath>

namespace rtsim {

/// True when the larger end sphere of a round cone (radii r0, r1 at centres `length` apart) holds
/// the smaller, |r1 - r0| >= length: the shape is then that sphere, with no cone between.
template <class T>
inline bool end_sphere_holds_other(T length, T r0, T r1) {
    return length <= std::fabs(r1 - r0);
}

}  // namespace rtsim
