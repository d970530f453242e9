#pragma once
// Wide BVHs behind the acceleration-structure seam (docs/accel.md, "Wide BVHs"): one Accel for
// every wide layout, on a Codec (wide_kernel.h: Fp32Codec<N>; traces/accel/cwbvh: the compressed
// nodes). Regions "nodes" (Codec::kBytes each) and "triangles" (HwTriangle, 48 bytes). Image
// params: {"order": "distance" | "octant"}.
//
// Validation (linear, messages built only on failure): every interior child after its parent
// and with one parent, leaves inside the triangle region, every triangle record in exactly one
// leaf, each node with 1..N children, the stack a ray can need within kWideStackLimit, plus the
// codec's own encoding checks. It also yields max_stack_entries(): the largest sum over a root
// path of (children - 1), the pushes a ray can have outstanding.
#include <memory>
#include <string>
#include <vector>

#include "traces/accel/accel.h"
#include "traces/accel/leaf_coverage.h"
#include "traces/accel/wide/wide_packet.h"
#include "traces/accel/wide/wide_stepper.h"
#include "traces/common/error.h"

namespace rtsim {

/// Instruction set of the fused loops: the best the CPU has (AVX for 8-wide nodes when present),
/// or the SSE2 baseline (tests run both).
enum class WideSimd : uint8_t { best = 0, sse2 = 1 };
/// True when the fused 8-wide loop runs its AVX node test on this CPU.
bool wide_simd_has_avx();
/// True when the CPU has `feature` ("avx", "avx2", "fma", "popcnt") and RTSIM_SIMD is not "sse2".
bool wide_simd_has(const char* feature);

/// The fused reference loop of the fp32 layouts (wide_trace.cpp): SIMD node tests with the same
/// per-lane arithmetic, and the same order and work as WideStepper<Fp32Codec<N>> in distance
/// order. N = 4, 6, 8. Needs view.valid (WideAccel sets it); without it, drives the stepper.
template <int N>
Hit trace_wide_fused(const WideView& view, const Ray& ray, TraversalMode mode, WorkCounts* work,
                     WideSimd simd = WideSimd::best);

/// Reads "order" from image params; throws rtsim::Error naming `source` if it is not a known order.
ChildOrder child_order_param(const AccelImage& image, const std::string& source);

/// Largest leaf a wide image may hold (the builders make leaves of at most kWideLeafMax).
constexpr uint32_t kWideMaxLeafTriangles = 1u << 16;

/// Structural validation of a wide image; returns the deepest stack a ray can need.
template <class Codec>
uint32_t validate_wide(const WideView& v, const std::string& source, const std::string& what) {
    if (v.node_count == 0) return 1;
    auto fail = [&](const std::string& m) -> void { throw Error(source + ": " + what + ": " + m); };
    auto at = [](uint64_t i, int s) { return "node " + std::to_string(i) + " slot " + std::to_string(s); };
    if (v.node_count >= (1ull << 32) || v.triangle_count >= (1ull << 32)) fail("more than 2^32 nodes or triangles");
    std::vector<uint32_t> need(v.node_count, 0);  // stack entries outstanding on entering a node
    std::vector<uint8_t> seen(v.node_count, 0);
    LeafCoverage covered(v.triangle_count);
    uint32_t max_stack = 1;
    DecodedNode d;
    for (uint64_t i = 0; i < v.node_count; ++i) {
        const auto& node = *reinterpret_cast<const typename Codec::Node*>(v.nodes + i * Codec::kBytes);
        if (i > 0 && !seen[i]) fail("node " + std::to_string(i) + " is not reachable from the root");
        Codec::check(node, i, fail);
        Codec::decode(node, d);
        const uint32_t k = detail::popcount8(d.valid);
        if (k == 0) fail("node " + std::to_string(i) + " has no children");
        const uint32_t pushes = need[i] + k - 1;
        if (pushes > kWideStackLimit) fail("a ray can need more than " + std::to_string(kWideStackLimit) + " stack entries");
        max_stack = std::max(max_stack, pushes);
        for (uint32_t m = d.valid; m; m &= m - 1) {
            const int s = __builtin_ctz(m);
            const uint32_t ref = d.ref[s], count = d.count[s];
            if (count == 0) {
                if (ref <= i || ref >= v.node_count)
                    fail(at(i, s) + " points to node " + std::to_string(ref) +
                         (ref < v.node_count ? " (not after its parent)" : " (out of range)"));
                if (seen[ref]) fail("node " + std::to_string(ref) + " has two parents");
                seen[ref] = 1;
                need[ref] = pushes;
                continue;
            }
            if (count > kWideMaxLeafTriangles) fail(at(i, s) + " is a leaf of " + std::to_string(count) + " triangles");
            covered.add(ref, count, fail, [&] { return at(i, s); });
        }
    }
    covered.finish(fail);
    return max_stack;
}

/// The locality tree of a wide image: a node brings itself and its leaf children's triangles; its
/// area is that of the (decoded) box its parent holds for it.
template <class Codec>
LocalityTree wide_locality_tree(const WideView& v) {
    LocalityTree t;
    std::vector<float> area(v.node_count, 0.0f);
    if (v.node_count) area[0] = std::numeric_limits<float>::infinity();
    std::vector<DecodedNode> decoded(v.node_count);
    for (uint64_t i = 0; i < v.node_count; ++i) {
        Codec::decode(*reinterpret_cast<const typename Codec::Node*>(v.nodes + i * Codec::kBytes), decoded[i]);
        const DecodedNode& d = decoded[i];
        for (uint32_t m = d.valid; m; m &= m - 1) {
            const int s = __builtin_ctz(m);
            if (d.count[s] != 0) continue;
            const float ex = d.hi[0][s] - d.lo[0][s], ey = d.hi[1][s] - d.lo[1][s], ez = d.hi[2][s] - d.lo[2][s];
            area[d.ref[s]] = ex * ey + ey * ez + ez * ex;
        }
    }
    for (uint64_t i = 0; i < v.node_count; ++i) {
        const DecodedNode& d = decoded[i];
        uint64_t bytes = Codec::kBytes;
        for (uint32_t m = d.valid; m; m &= m - 1) bytes += uint64_t(d.count[__builtin_ctz(m)]) * sizeof(HwTriangle);
        t.add_node(bytes, area[i]);
        for (uint32_t m = d.valid; m; m &= m - 1)
            if (d.count[__builtin_ctz(m)] == 0) t.add_child(d.ref[__builtin_ctz(m)]);
    }
    t.finish();
    return t;
}

template <class Codec>
class WideAccel final : public Accel {
public:
    WideAccel(AccelImage image, const std::string& source) : Accel(std::move(image)) {
        const Region& nodes = m_image.region("nodes");
        const Region& tris = triangle_region(m_image);
        require(nodes.record_bytes == Codec::kBytes && triangle_records_ok(tris),
                source + ": " + m_image.kind + " regions must hold " + std::to_string(Codec::kBytes) +
                    "-byte nodes and 48-byte triangles");
        m_view.nodes = nodes.bytes.data();
        m_view.node_count = nodes.count;
        m_view.node_base = nodes.base;
        m_triangles = TriangleStore::open(m_image, source);
        m_view.triangles = m_triangles.triangles();
        m_view.triangle_count = m_triangles.count();
        m_view.tri_at = m_triangles.addressing();
        m_view.curved = has_curved();
        m_view.order = child_order_param(m_image, source);
        m_view.max_stack = validate_wide<Codec>(m_view, source, m_image.kind);
        m_valid.resize(m_view.node_count);
        for (uint64_t i = 0; i < m_view.node_count; ++i)
            m_valid[i] = uint8_t(Codec::valid_mask(
                *reinterpret_cast<const typename Codec::Node*>(m_view.nodes + i * Codec::kBytes)));
        m_view.valid = m_valid.data();
    }

    std::unique_ptr<Stepper> make_stepper(const StepOptions& options = {}) const override {
        return std::make_unique<WideStepper<Codec>>(m_view, options.short_stack_entries, options.box_precision_bits,
                                                    options.quantized_box_tests, options.anyhit_order);
    }
    Hit trace(const Ray& ray, TraversalMode mode, WorkCounts* work = nullptr,
              const StepOptions& options = {}) const override {
        if constexpr (Codec::kFused) {
            if (m_view.order == ChildOrder::distance && options.fused_loop_walks_alike())
                return Codec::fused(m_view, ray, mode, work);
        }
        return Accel::trace(ray, mode, work, options);
    }
    std::unique_ptr<PacketStepper> make_packet_stepper(const StepOptions& options = {}) const override {
        auto s = std::make_unique<WidePacketStepper<Codec>>(m_view);
        s->set_anyhit_order(options.anyhit_order);
        return s;
    }
    void trace_packet(const Ray* rays, const TraversalMode* modes, uint32_t n, Hit* hits, WorkCounts* work,
                      PacketCounts* counts, float split_below = 0.0f, const StepOptions& options = {}) const override {
        trace_packet_wide<Codec>(m_view, rays, modes, n, hits, work, counts, split_below, options.anyhit_order);
    }
    LocalityPartition partition(uint64_t budget_bytes) const override {
        require(budget_bytes >= Codec::kBytes, "treelet budget must be at least one node (" +
                                                   std::to_string(Codec::kBytes) + " bytes)");
        return partition_tree(wide_locality_tree<Codec>(m_view), budget_bytes);
    }
    std::vector<OpKind> op_kinds() const override {
        return with_record_kinds({OpKind::box, OpKind::triangle});
    }
    uint32_t max_stack_entries() const override { return m_view.max_stack; }
    const WideView& view() const { return m_view; }

private:
    WideView m_view;
    std::vector<uint8_t> m_valid;
};

}  // namespace rtsim
