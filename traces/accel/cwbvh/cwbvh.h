#pragma once
// Compressed wide BVHs behind the seam (docs/accel.md, "cwbvh8, cwbvh6"): the wide build tree
// (traces/accel/wide/wide_tree.h) serialised as CwNode8 / CwNode6 (cwbvh_layout.h), children and
// leaf triangles of a node contiguous (wide_order), traversed by the one wide stepper on a codec
// that dequantises child boxes to floats (rounding outward, so no false misses).
#include <memory>
#include <string>

#include "traces/accel/cwbvh/cwbvh_layout.h"
#include "traces/accel/wide/wide.h"

namespace rtsim {

inline uint32_t cw_base_node(const CwNode8& n) { return n.base_node; }
inline uint32_t cw_base_tri(const CwNode8& n) { return n.base_tri; }
inline uint32_t cw_base_node(const CwNode6& n) { return n.base_node(); }
inline uint32_t cw_base_tri(const CwNode6& n) { return n.base_tri(); }

/// A compressed node as a wide-stepper codec (wide_kernel.h).
template <class N, int W>
struct CwCodec {
    using Node = N;
    static constexpr int kWidth = W;
    static constexpr uint32_t kBytes = sizeof(N);
    /// CwNode8 has a fused SIMD reference loop (cwbvh_trace.cpp); CwNode6, the stepper.
    static constexpr bool kFused = W == 8;
    /// Child boxes are 8-bit integers on the node's grid: an integer box test can run on them.
    static constexpr bool kQuantized = true;
    /// The node's grid cell per axis (one step of its 8-bit child coordinates).
    static void cell(const Node& n, float cell[3]) {
        for (int a = 0; a < 3; ++a) cell[a] = quant_scale(n.e[a]);
    }
    static Hit fused(const WideView& view, const Ray& ray, TraversalMode mode, WorkCounts* work);

    static uint32_t valid_mask(const Node& n) {
        uint32_t m = 0;
        for (int s = 0; s < W; ++s) m |= uint32_t(n.meta[s] != 0) << s;
        return m;
    }
    static void decode(const Node& n, DecodedNode& d) {
        d.valid = 0;
        uint32_t rank = 0;
        for (int s = 0; s < W; ++s) {
            const uint8_t m = n.meta[s];
            if (m == 0) continue;
            d.valid |= 1u << s;
            for (int a = 0; a < 3; ++a) {
                d.lo[a][s] = quant_decode(n.p[a], n.e[a], n.qlo[a][s]);
                d.hi[a][s] = quant_decode(n.p[a], n.e[a], n.qhi[a][s]);
            }
            if (meta_is_interior(m)) {
                d.ref[s] = cw_base_node(n) + rank++;
                d.count[s] = 0;
            } else {
                d.ref[s] = cw_base_tri(n) + meta_leaf_offset(m);
                d.count[s] = meta_leaf_count(m);
            }
        }
    }
    /// Encoding checks: exponent bytes in 1..254, meta bytes of a known form (interior: slot + 24;
    /// leaf: unary count 1..3, offset + count <= 3 W), CwNode8's imask equal to meta's interiors.
    template <class Fail>
    static void check(const Node& n, uint64_t index, const Fail& fail) {
        for (int a = 0; a < 3; ++a)
            if (n.e[a] == 0 || n.e[a] == 255) fail("node " + std::to_string(index) + " has exponent byte 0 or 255");
        uint32_t interior = 0;
        for (int s = 0; s < W; ++s) {
            const uint8_t m = n.meta[s];
            if (m == 0) continue;
            const auto bad = [&] { fail("node " + std::to_string(index) + " slot " + std::to_string(s) + " has meta byte " + std::to_string(m)); };
            if (meta_is_interior(m)) {
                if ((m & 31) != 24 + s) bad();
                interior |= 1u << s;
            } else if (const uint32_t top = m >> 5u; top != 1 && top != 3 && top != 7) {
                bad();
            } else if (meta_leaf_offset(m) + meta_leaf_count(m) > 3u * W) {
                bad();
            }
        }
        if constexpr (W == 8)
            if (n.imask != interior) fail("node " + std::to_string(index) + " imask disagrees with its meta bytes");
    }
};

using Cw8Codec = CwCodec<CwNode8, 8>;
using Cw6Codec = CwCodec<CwNode6, 6>;

/// The compressed image (kind e.g. "cwbvh8") of a wide tree of width 8 (CwNode8) or 6 (CwNode6).
/// Throws rtsim::Error if the tree has leaves of more than 3 triangles or, for CwNode6, more
/// than 2^28 nodes or triangles.
AccelImage cwbvh_image(const WideBuildTree& tree, const Scene& scene, const std::string& kind, ChildOrder order);

/// SAH cost of a compressed image (from cwbvh_image) as the hardware sees it: C_t per node and
/// C_i per triangle, each weighted by the area of the box its parent stores for it, dequantised
/// outward as the node step tests it (relative to the root's area). The wide tree's
/// wide_sah_cost() uses the exact boxes; the quantised ones are larger, so this is higher.
double cwbvh_sah_cost(const AccelImage& image, float traversal_cost, float intersection_cost);

/// The fused reference loop of cwbvh8 images in distance order (cwbvh_trace.cpp): SIMD decoding
/// of each node's child boxes, the hits and work of WideStepper<Cw8Codec>. Needs view.valid.
Hit trace_cwbvh8_fused(const WideView& view, const Ray& ray, TraversalMode mode, WorkCounts* work,
                       WideSimd simd = WideSimd::best);
template <>
Hit Cw8Codec::fused(const WideView& view, const Ray& ray, TraversalMode mode, WorkCounts* work);

/// The Accel of a compressed image of width 8 or 6.
std::unique_ptr<Accel> load_cwbvh(AccelImage image, int width, const std::string& source);

}  // namespace rtsim
