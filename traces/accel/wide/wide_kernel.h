#pragma once
// The node step every wide layout shares (docs/accel.md, "Wide BVHs"): a node is decoded to float
// child boxes (fp32 nodes copy theirs, compressed nodes dequantise theirs, rounding outward), each
// child box is tested with the one robust box arithmetic (traces/isect/ray_box_kernel.h), and the
// children hit are ordered: front to back by entry distance (ties to the lower slot), or in
// Ylitie et al.'s octant order (slot XOR ray octant, no sort). The nearest is visited next, the
// others pushed farthest first. Steppers and fused loops call these same functions.
#include <cmath>
#include <cstdint>

#include "traces/accel/step_options.h"
#include "traces/accel/wide/wide_layout.h"
#include "traces/accel/wide/wide_tree.h"
#include "traces/isect/ray_box_kernel.h"

namespace rtsim {

struct WideView;

/// A wide node decoded to floats: what every wide layout's node step tests.
struct DecodedNode {
    uint32_t valid = 0;  ///< bit s: slot s holds a child
    float lo[3][kMaxWideWidth];
    float hi[3][kMaxWideWidth];
    uint32_t ref[kMaxWideWidth];    ///< interior child: node index; leaf: first triangle
    uint32_t count[kMaxWideWidth];  ///< 0: interior child; else the leaf's triangle count
};

/// How a node's hit children are ordered (image params "order").
enum class ChildOrder : uint8_t {
    distance = 0,  ///< front to back: entry distance, ties to the lower slot
    octant = 1,    ///< Ylitie, Karras & Laine 2017, section 3.2: slot XOR the ray's octant
};

/// Stack entry of every wide stepper and fused loop: a child to visit and its entry distance.
struct WideStackEntry {
    uint32_t ref;
    uint32_t count;
    float tnear;
};

/// Most stack entries a wide image may need (7 pushes per level, 64 levels).
constexpr uint32_t kWideStackLimit = 7 * 64;

/// The fp32 layout as a codec: which slots hold children, and the floats they hold.
template <int N>
struct Fp32Codec {
    using Node = WideNode<N>;
    static constexpr int kWidth = N;
    static constexpr uint32_t kBytes = sizeof(Node);
    static constexpr bool kFused = true;  ///< has a fused SIMD reference loop (wide_trace.cpp)
    /// Child boxes stored as fp32: no quantisation grid for an integer box test.
    static constexpr bool kQuantized = false;
    static void cell(const Node&, float cell[3]) { cell[0] = cell[1] = cell[2] = 0.0f; }
    /// The fused loop (distance order only): trace_wide_fused<N> (wide_accel.h).
    static Hit fused(const WideView& view, const Ray& ray, TraversalMode mode, WorkCounts* work);

    /// Encoding checks beyond the generic ones: none (any count and box is well-formed).
    template <class Fail>
    static void check(const Node&, uint64_t, const Fail&) {}
    static uint32_t valid_mask(const Node& n) {
        uint32_t m = 0;
        for (int s = 0; s < N; ++s) m |= uint32_t(n.child_count[s] != kEmptyChild) << s;
        return m;
    }
    static void decode(const Node& n, DecodedNode& d) {
        d.valid = valid_mask(n);
        for (int s = 0; s < N; ++s) {
            for (int a = 0; a < 3; ++a) {
                d.lo[a][s] = n.lo(s, a);
                d.hi[a][s] = n.hi(s, a);
            }
            d.ref[s] = n.child_ref[s];
            d.count[s] = n.child_count[s];
        }
    }
};

namespace detail {

/// Set bits of a slot mask (at most 8 bits) without a library call: SSE2 builds have no POPCNT
/// instruction, and __builtin_popcount becomes a call to libgcc in the hot loop.
inline uint32_t popcount8(uint32_t m) {
    m = m - ((m >> 1) & 0x55u);
    m = (m & 0x33u) + ((m >> 2) & 0x33u);
    return (m + (m >> 4)) & 0x0Fu;
}

/// Bit a set where the ray's direction is negative on axis a (the sign of 1/d; -0 counts).
inline uint32_t ray_octant(const RayBoxPre& pre) {
    return uint32_t(std::signbit(pre.inv_dir4[0])) | uint32_t(std::signbit(pre.inv_dir4[1])) << 1 |
           uint32_t(std::signbit(pre.inv_dir4[2])) << 2;
}

/// Tests every valid child box against [tmin, cull]; returns the mask of children hit and
/// writes their entry distances.
inline uint32_t wide_box_tests(const RayBoxPre& pre, const DecodedNode& n, float tmin, float cull,
                               float tnear[kMaxWideWidth]) {
    uint32_t mask = 0;
    for (uint32_t v = n.valid; v; v &= v - 1) {
        const int s = __builtin_ctz(v);
        const float lo[3] = {n.lo[0][s], n.lo[1][s], n.lo[2][s]};
        const float hi[3] = {n.hi[0][s], n.hi[1][s], n.hi[2][s]};
        if (box_kernel(pre, lo, hi, tmin, cull, &tnear[s])) mask |= 1u << s;
    }
    return mask;
}

/// The hit slots in visit order; returns how many. out[0] is visited next; out[n-1] .. out[1]
/// are pushed in that order, so they pop nearest first. Slots arrive in increasing order and
/// the insertion is stable, so equal keys keep the lower slot first.
__attribute__((always_inline)) inline int order_children(uint32_t mask, const float tnear[kMaxWideWidth], ChildOrder order,
                          uint32_t octant, uint8_t out[kMaxWideWidth]) {
    int n = 0;
    for (uint32_t m = mask; m; m &= m - 1) {
        const uint8_t s = uint8_t(__builtin_ctz(m));
        int i = n++;
        if (order == ChildOrder::distance) {
            while (i > 0 && tnear[out[i - 1]] > tnear[s]) out[i] = out[i - 1], --i;
        } else {
            while (i > 0 && (out[i - 1] ^ octant) > (s ^ octant)) out[i] = out[i - 1], --i;
        }
        out[i] = s;
    }
    return n;
}

/// Half the surface area of child slot s's box.
inline float wide_half_area(const DecodedNode& n, int s) {
    const float dx = n.hi[0][s] - n.lo[0][s], dy = n.hi[1][s] - n.lo[1][s], dz = n.hi[2][s] - n.lo[2][s];
    return dx * dy + dy * dz + dz * dx;
}

/// The hit slots of an any-hit ray in an AnyHitOrder other than nearest (as order_children
/// lays them out): largest_box puts larger child boxes first (more likely to hold an occluder,
/// as the binary BVH's order), fixed keeps slot order (no sort). Equal areas keep the lower slot.
inline int order_children_anyhit(uint32_t mask, const DecodedNode& n, AnyHitOrder order, uint8_t out[kMaxWideWidth]) {
    int count = 0;
    float area[kMaxWideWidth];
    for (uint32_t m = mask; m; m &= m - 1) {
        const uint8_t s = uint8_t(__builtin_ctz(m));
        int i = count++;
        if (order == AnyHitOrder::largest_box) {
            area[s] = wide_half_area(n, s);
            while (i > 0 && area[out[i - 1]] < area[s]) out[i] = out[i - 1], --i;
        }
        out[i] = s;
    }
    return count;
}

}  // namespace detail
}  // namespace rtsim
