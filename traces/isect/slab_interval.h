#pragma once
// The robust slab test (ray_box_kernel.h) kept incrementally, for structures that cut space with
// planes (kd-trees, BIH, octrees): a ray's interval in a cell is the fold of its near and far
// plane distances, and a child cell differs from its parent by one plane (a kd split, a BIH clip
// plane) or by one plane per axis (an octree's mid planes). Folding the new plane's distance into
// the parent's interval gives exactly what box_kernel computes on the child's box, because a
// slab distance (plane - o) * (1 / d) is monotone in the plane (IEEE subtraction and
// multiplication by a fixed value are) and the folds ignore NaN in the same way. So these
// structures visit exactly the cells the robust box test accepts, and the argument that a BVH
// misses no hit (docs/intersection.md) carries over: a cell whose part of a triangle the ray
// truly hits is always entered, at or before the hit.
#include <cmath>
#include <limits>

#include "traces/isect/ray_box.h"
#include "traces/isect/ray_box_kernel.h"

namespace rtsim::detail {

/// A ray's parameter interval in a cell, unwidened: tn the largest near-plane distance (and
/// tmin), tf the smallest far-plane distance.
struct SlabInterval {
    float tn = 0.0f;
    float tf = std::numeric_limits<float>::infinity();
};

/// Distance along the ray to `plane` of `axis`, as the box test computes it.
inline float slab_distance(const RayBoxPre& pre, int axis, float plane) {
    return (plane - pre.origin4[axis]) * pre.inv_dir4[axis];
}
/// True when the ray runs towards lower coordinates on `axis` (the sign bit of 1/d, so -0 too).
inline bool slab_negative(const RayBoxPre& pre, int axis) { return std::signbit(pre.inv_dir4[axis]); }

/// The folds of box_kernel: NaN distances (a ray lying in a plane) leave the value unchanged.
inline void fold_near(float& tn, float n) { tn = n > tn ? n : tn; }
inline void fold_far(float& tf, float f) { tf = f < tf ? f : tf; }

/// The box test's verdict: the widened far distance, capped at tmax, is not before tn.
inline bool slab_hit(const SlabInterval& s, float tmax) {
    float tf = s.tf * (s.tf >= 0.0f ? kFarUp : kFarDown);
    tf = tf < tmax ? tf : tmax;
    return s.tn <= tf;
}

/// The interval in a box (box_kernel's folds, x then y then z).
inline SlabInterval slab_box(const RayBoxPre& pre, const float lo[3], const float hi[3], float tmin) {
    SlabInterval s{tmin, std::numeric_limits<float>::infinity()};
    for (int a = 0; a < 3; ++a) {
        const bool neg = slab_negative(pre, a);
        fold_near(s.tn, slab_distance(pre, a, neg ? hi[a] : lo[a]));
        fold_far(s.tf, slab_distance(pre, a, neg ? lo[a] : hi[a]));
    }
    return s;
}

/// The interval in a box whose plane distances are known: tlo[a] and thi[a] the distances to its
/// low and high plane of axis a (box_kernel's folds on the same values, x then y then z).
inline SlabInterval slab_planes(const float tlo[3], const float thi[3], const bool negative[3], float tmin) {
    SlabInterval s{tmin, std::numeric_limits<float>::infinity()};
    for (int a = 0; a < 3; ++a) {
        fold_near(s.tn, negative[a] ? thi[a] : tlo[a]);
        fold_far(s.tf, negative[a] ? tlo[a] : thi[a]);
    }
    return s;
}

/// The part of `s` on the low side of a plane at distance t on an axis (x <= plane): the plane
/// is the cell's far plane when the ray runs up the axis, its near plane when it runs down.
inline SlabInterval slab_below(SlabInterval s, float t, bool negative) {
    if (negative) fold_near(s.tn, t);
    else fold_far(s.tf, t);
    return s;
}
/// The part on the high side (x >= plane).
inline SlabInterval slab_above(SlabInterval s, float t, bool negative) {
    if (negative) fold_far(s.tf, t);
    else fold_near(s.tn, t);
    return s;
}

}  // namespace rtsim::detail
