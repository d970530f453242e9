#pragma once
// Triangle clipping for spatial splits (Stich, Friedrich & Dietrich 2009, section 4.3: a
// reference straddling a plane is split by clipping its triangle, not its box). A reference is
// the part of its triangle inside its box. Clipping runs in double on the triangle's polygon
// (Sutherland & Hodgman 1974, one half-space at a time), and every box it returns is rounded
// outward to float and then intersected with the exact float bounds it must lie in (the
// reference's box, the bin's slab), so a box always contains the exact part of the triangle it
// stands for: a ray can never miss a spatially split triangle (docs/accel.md, "sbvh").
#include <cstdint>

#include "traces/common/aabb.h"
#include "traces/scene/scene.h"

namespace rtsim {

/// The part of `tri` inside `box`, as a convex polygon in double.
class ClippedTriangle {
public:
    ClippedTriangle(const Triangle& tri, const Aabb& box);

    /// Boxes of the polygon's pieces between consecutive planes of `axis`, for binning:
    /// out[k] is the part in [planes[k], planes[k + 1]] for k in 0..count-1 (planes ascending),
    /// rounded to nearest (an estimate to price splits with, not a bound); pieces the triangle
    /// does not reach are empty boxes.
    void chop(int axis, const float* planes, uint32_t count, Aabb* out) const;
    /// The parts on either side of plane `position` of `axis`: conservative (each contains the
    /// exact part and lies in the reference box and its half-space), maybe empty.
    void split(int axis, float position, Aabb* left, Aabb* right) const;
    bool empty() const { return m_poly.n == 0; }
    /// Area of the triangle's part in the box (in double; 0 when it vanished there).
    double area() const;

private:
    static constexpr int kMaxVertices = 16;
    struct DBox;  ///< a box in double
    struct Polygon {
        double v[kMaxVertices][3];
        int n = 0;
    };
    /// Keeps the part with sign * (p[axis] - position) >= 0; the new vertices lie on the plane.
    static void clip(const Polygon& in, int axis, double position, double sign, Polygon* out);
    /// Grows `a` (and `b`, if given) by the points where the polygon's edges cross plane s.
    void grow_crossings(int axis, double s, DBox* a, DBox* b) const;
    /// A piece's box (in double) rounded outward by the clipping error bound, then intersected
    /// with the reference box and the slab [lo, hi] of `axis`.
    Aabb conservative_box(const DBox& piece, int axis, float lo, float hi) const;

    Polygon m_poly;
    Aabb m_box;         ///< the reference's box
    double m_margin;    ///< bound on the absolute error of a clipped coordinate
};

}  // namespace rtsim
