#pragma once
// The binary BVH's traversal rules shared by its stepper (bvh2_stepper.cpp) and its fused loop
// (bvh2_trace.cpp): child selection at a node. The leaf's hit rules and the cull distance are
// every structure's (traces/isect/leaf_kernel.h). Both call these same inline functions, so they
// visit the same nodes in the same order, count the same work and keep the same hits
// (docs/intersection.md; a test drives both on every ray).
#include <cmath>
#include <cstdint>

#include "traces/accel/step_options.h"
#include "traces/bvh/hw_layout.h"
#include "traces/common/ray.h"
#include "traces/isect/leaf_kernel.h"
#include "traces/isect/ray_box_kernel.h"

namespace rtsim {

/// Entries of the binary BVH's traversal stack (the builder's max_depth keeps trees within it).
constexpr int kTraversalStackSize = 64;

namespace detail {

/// Throws rtsim::Error: a push onto a full traversal stack (kTraversalStackSize entries).
[[noreturn]] void throw_stack_overflow();

#if defined(__SSE2__)
/// Node step on SIMD lanes: both child boxes against [tmin, cull] (in every lane of tmin4 and
/// cull4), empty slots dropped. Returns the 2-bit mask of children hit; lanes 0 and 1 of
/// *tnear are their entry distances.
inline unsigned node_step_sse(const RayBoxPre& pre, const HwNode& node, __m128 tmin4,
                              __m128 cull4, __m128* tnear) {
    const unsigned mask = node_kernel_sse(pre, node, tmin4, cull4, tnear);
    // Empty slots never hit, whatever their box holds.
    const __m128i counts = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(node.child_count));
    const __m128i empty = _mm_cmpeq_epi32(counts, _mm_set1_epi32(int32_t(kEmptyChild)));
    return mask & ~unsigned(_mm_movemask_ps(_mm_castsi128_ps(empty))) & 3u;
}
#endif

/// Node step: both child boxes against [tmin, cull], empty slots dropped. Returns the 2-bit
/// mask of children hit and their entry distances.
inline unsigned node_step(const RayBoxPre& pre, const HwNode& node, float tmin, float cull,
                          float tnear[2]) {
#if defined(__SSE2__)
    __m128 tn;
    const unsigned mask = node_step_sse(pre, node, _mm_set1_ps(tmin), _mm_set1_ps(cull), &tn);
    _mm_storel_pi(reinterpret_cast<__m64*>(tnear), tn);
    return mask;
#else
    const unsigned mask = node_kernel(pre, node, tmin, cull, tnear);
    return mask & ~(unsigned(node.child_count[0] == kEmptyChild) |
                    (unsigned(node.child_count[1] == kEmptyChild) << 1));
#endif
}

/// The slot to visit next among the hit ones (mask != 0): the nearer, child 0 on equal entry
/// distances. When both hit, the other slot (returned ^ 1) is pushed.
inline unsigned next_slot(unsigned mask, const float tnear[2]) {
    if (mask == 3) return tnear[1] < tnear[0] ? 1u : 0u;
    return mask >> 1;
}

/// Half the surface area of a child slot's box (enough to compare two boxes).
inline float half_area(const HwNode& node, int child) {
    const float dx = node.hi(child, 0) - node.lo(child, 0);
    const float dy = node.hi(child, 1) - node.lo(child, 1);
    const float dz = node.hi(child, 2) - node.lo(child, 2);
    return dx * dy + dy * dz + dz * dx;
}

/// The slot to visit next by an any-hit order (AnyHitOrder): a larger box is more likely to
/// hold an occluder (the surface-area argument of MacDonald & Booth 1990 applied to shadow
/// rays), and a fixed order saves the sort. Child 0 on equal areas.
inline unsigned next_slot(unsigned mask, const float tnear[2], const HwNode& node, AnyHitOrder order) {
    if (mask != 3 || order == AnyHitOrder::nearest) return next_slot(mask, tnear);
    if (order == AnyHitOrder::fixed) return 0u;
    return half_area(node, 1) > half_area(node, 0) ? 1u : 0u;
}

/// A traversal-stack entry of a binary walk: the child to resume at and its entry distance.
struct Bvh2StackEntry {
    uint32_t ref;    ///< node index, or first record of a leaf
    uint32_t count;  ///< 0: node; else the leaf's record count
    float tnear;
};

/// One node step of a binary walk (the BVH's stepper and the two-level TLAS walk): counts the
/// step and its two box tests, pushes the farther hit child onto stack[size++] and names the
/// nearer (or the first by an any-hit `order`) in *ref / *count. Returns false when no child is hit (the caller pops).
inline bool descend(const RayBoxPre& pre, const HwNode& node, float tmin, float cull, WorkCounts& work,
                    Bvh2StackEntry* stack, int& size, uint32_t* ref, uint32_t* count,
                    AnyHitOrder order = AnyHitOrder::nearest) {
    work.steps += 1;
    work.box_tests += 2;
    float tnear[2];
    const unsigned mask = node_step(pre, node, tmin, cull, tnear);
    if (mask == 0) return false;
    const unsigned next = next_slot(mask, tnear, node, order);
    if (mask == 3) {
        const unsigned far = next ^ 1u;
        if (size >= kTraversalStackSize) throw_stack_overflow();
        stack[size++] = {node.child_ref[far], node.child_count[far], tnear[far]};
    }
    *ref = node.child_ref[next];
    *count = node.child_count[next];
    return true;
}

}  // namespace detail
}  // namespace rtsim
