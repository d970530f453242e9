#pragma once
// Directed rounding of a double to float: the boxes that must hold what they bound (a clipped
// triangle's, a sphere's) round their corners outward.
#include <cmath>
#include <limits>

namespace rtsim {

/// Largest float <= x.
inline float round_down(double x) {
    const float f = float(x);
    return double(f) > x ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}
/// Smallest float >= x.
inline float round_up(double x) {
    const float f = float(x);
    return double(f) < x ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

}  // namespace rtsim
