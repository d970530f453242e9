#pragma once
// The stepper of every wide BVH layout, fp32 or compressed (docs/accel.md, "Wide BVHs"), on a
// Codec that says where a node's children are and decodes its boxes to floats (wide_kernel.h).
//
// Steps: a node step fetches the node's bytes (several lines when it spans them: 128, 192, 256
// bytes fp32; 64 or 80 compressed) and runs one box test per child (empty slots are neither
// tested nor counted); its locality key is the node. The children hit are ordered
// (wide_kernel.h): the first is visited next, the others pushed farthest first; any-hit rays may
// take another order (traversal.anyhit_order: larger boxes first, or slot order). A leaf step
// fetches the leaf's triangles (contiguous) and runs one triangle test each, plus an alpha test
// for each MASK triangle hit. Popped entries entered beyond the best hit are dropped unfetched.
// Hit rules, cull distance and any-hit termination are every structure's (leaf_kernel.h).
// With a short stack (set by the Accel; traces/accel/short_stack.h) a restart's re-descent adds
// node steps of the same shape, counted in the model-only restart fields. With reduced-precision
// box tests (traces/accel/rp_boxes.h) the subtrees only the narrower test enters add node and
// leaf steps of the same shapes, counted in the model-only rp_* fields.
#include <cstdint>
#include <string>
#include <vector>

#include "traces/accel/leaf_blocks.h"
#include "traces/accel/rp_boxes.h"
#include "traces/accel/short_stack.h"
#include "traces/accel/stack_reads.h"
#include "traces/accel/stepper.h"
#include "traces/accel/wide/wide_kernel.h"
#include "traces/common/error.h"
#include "traces/common/hw_triangle.h"
#include "traces/isect/leaf_kernel.h"
#include "traces/isect/ray_box_rp.h"
#include "traces/isect/ray_triangle.h"

namespace rtsim {

/// Where a wide BVH's data lives: arrays, their addresses, and how it is traversed.
struct WideView {
    const uint8_t* nodes = nullptr;  ///< node records of Codec::kBytes each
    const HwTriangle* triangles = nullptr;
    uint64_t node_count = 0;
    uint64_t triangle_count = 0;
    uint64_t node_base = 0;      ///< address of node 0
    TriangleAddressing tri_at;   ///< where triangles' bytes are (plain or compressed leaves)
    bool curved = false;         ///< some records are curved: leaves split their tests by kind
    ChildOrder order = ChildOrder::distance;
    uint32_t max_stack = 1;  ///< deepest stack a ray can need (from validation)
    /// Host-side copy of each node's slot mask, derived from the image when it is loaded (not
    /// part of the image): the fused loops read one byte instead of decoding it per node.
    const uint8_t* valid = nullptr;
};

template <class Codec>
class WideStepper final : public Stepper {
public:
    /// quantized_box_tests: the narrower test is the integer test of quantised nodes (below;
    /// only codecs with kQuantized), instead of box_precision_bits' reduced fp test.
    explicit WideStepper(const WideView& view, uint32_t short_stack_entries = 0, uint32_t box_precision_bits = 0,
                         bool quantized_box_tests = false, AnyHitOrder anyhit_order = AnyHitOrder::nearest)
        : m_view(view), m_anyhit_order(anyhit_order), m_stack(std::max<uint32_t>(1, view.max_stack)) {
        m_short.configure(short_stack_entries);
        if (m_short.enabled()) m_entry_depth.resize(m_stack.size());
        m_quantized = quantized_box_tests && Codec::kQuantized;
        m_rp.configure(m_quantized ? kQuantizedTestBits : box_precision_bits);
        if (m_rp.enabled()) m_rp_tnear.resize(m_stack.size());
    }

    void begin(const Ray& ray, TraversalMode mode) override {
        m_ray = ray;
        m_mode = mode;
        m_hit = Hit{};
        m_work = WorkCounts{};
        m_stack_size = 0;
        m_depth = 0;
        m_short.begin();
        m_rp.begin();
        if (!ray_is_valid(ray) || m_view.node_count == 0) return finish();
        m_box = ray_box_precompute(ray);
        m_tri = ray_triangle_precompute(ray);
        m_octant = detail::ray_octant(m_box);
        m_hit.t = ray.tmax;  // while traversing: the best distance so far
        m_cull_t = detail::cull_distance(ray.tmax);
        m_ref = 0;
        m_count = 0;
        plan_next();
    }

    StepOutcome execute() override {
        StepOutcome out;
        if (m_plan.done) return out;
        if (m_rp.walking()) return rp_step(), out;
        if (m_short.replaying()) replay_step();
        else if (m_count == 0) visit_node(node(m_ref));
        else out.add_op(OpKind::anyhit, visit_leaf());
        // Boxes only the reduced-precision test entered are walked before the step just planned.
        if (m_rp.pending()) m_rp.start(m_plan), plan_at(m_rp.next().ref, m_rp.next().count);
        return out;
    }

    uint32_t stack_reads(Fetch* out, uint32_t max) const override {
        return tree_stack_reads(m_stack.data(), m_stack_size, m_view.node_base, Codec::kBytes, m_view.tri_at, out, max);
    }

private:
    using Node = typename Codec::Node;
    const Node& node(uint32_t i) const {
        return *reinterpret_cast<const Node*>(m_view.nodes + uint64_t(i) * Codec::kBytes);
    }

    void plan_node(uint32_t i) {
        m_plan.reset(i);
        m_plan.add_fetch(m_view.node_base + uint64_t(i) * Codec::kBytes, Codec::kBytes, DataKind::node);
        m_plan.add_op(OpKind::box, detail::popcount8(Codec::valid_mask(node(i))));
    }

    void plan_next() { plan_at(m_ref, m_count); }
    void plan_at(uint32_t ref, uint32_t count) {  // a node (count 0) or a leaf's triangles
        if (count == 0) {
            plan_node(ref);
        } else {
            m_plan.reset(kNoLocality);  // a leaf's triangles belong to its node's treelet
            const TriangleAddressing::Span s = m_view.tri_at.span(ref, count);
            m_plan.add_fetch(s.address, s.bytes, DataKind::triangle);
            const detail::LeafTests t = detail::leaf_tests(m_view.triangles + ref, count, m_view.curved);
            m_plan.add_leaf_ops(t);
        }
    }

    void visit_node(const Node& n) {
        DecodedNode d;
        Codec::decode(n, d);
        m_work.steps += 1;
        m_work.box_tests += detail::popcount8(d.valid);
        float tnear[kMaxWideWidth];
        const uint32_t mask = detail::wide_box_tests(m_box, d, m_ray.tmin, m_cull_t, tnear);
        float rp_tnear[kMaxWideWidth];
        if (m_rp.enabled()) rp_tests(n, d, mask, rp_tnear);
        uint8_t order[kMaxWideWidth];
        const bool reordered = m_mode == TraversalMode::any_hit && m_anyhit_order != AnyHitOrder::nearest;
        const int hits = reordered ? detail::order_children_anyhit(mask, d, m_anyhit_order, order)
                                   : detail::order_children(mask, tnear, m_view.order, m_octant, order);
        if (m_short.enabled()) m_short.visit(m_ref, m_depth);
        if (hits == 0) return pop_next();
        for (int i = hits - 1; i >= 1; --i) {
            if (uint32_t(m_stack_size) >= m_stack.size())
                throw Error("wide BVH: traversal stack overflow (" + std::to_string(m_stack.size()) + " entries)");
            if (m_short.enabled()) {
                m_entry_depth[size_t(m_stack_size)] = m_depth + 1;
                if (m_short.push()) m_work.stack_drops += 1;
            }
            if (m_rp.enabled()) m_rp_tnear[size_t(m_stack_size)] = rp_tnear[order[i]];
            m_stack[size_t(m_stack_size++)] = {d.ref[order[i]], d.count[order[i]], tnear[order[i]]};
        }
        m_depth += 1;
        m_ref = d.ref[order[0]];
        m_count = d.count[order[0]];
        plan_next();
    }

    uint32_t visit_leaf() {
        const detail::LeafTests t = detail::leaf_tests(m_view.triangles + m_ref, m_count, m_view.curved);
        detail::count_leaf_tests(m_work, t);
        const uint32_t alpha_before = m_work.anyhit_calls;
        const HwTriangle* tris = m_view.triangles + m_ref;
        const bool done = m_mode == TraversalMode::any_hit
                              ? detail::leaf_step<true>(m_tri, m_ray.tmin, m_ray.tmax, tris, m_count, m_hit,
                                                        m_cull_t, m_work.anyhit_calls)
                              : detail::leaf_step<false>(m_tri, m_ray.tmin, m_ray.tmax, tris, m_count, m_hit,
                                                         m_cull_t, m_work.anyhit_calls);
        if (done) finish();
        else pop_next();
        return m_work.anyhit_calls - alpha_before;
    }

    void pop_next() {
        // With a short stack, reaching an entry it dropped means a restart (short_stack.h).
        bool restart = false;
        while (m_stack_size > 0) {
            const WideStackEntry& e = m_stack[size_t(--m_stack_size)];
            if (m_short.enabled()) restart |= m_short.pop();
            if (e.tnear > m_cull_t) {
                // The narrower test's entry distance may be near enough: the hardware visits it.
                if (m_rp.enabled() && m_rp_tnear[size_t(m_stack_size)] <= m_cull_t)
                    m_work.rp_box_hits += 1, m_rp.enter(e.ref, e.count);
                continue;
            }
            m_ref = e.ref;
            m_count = e.count;
            if (m_short.enabled()) m_depth = m_entry_depth[size_t(m_stack_size)];
            if (restart) return begin_restart(m_depth, true);
            return plan_next();
        }
        if (restart) return begin_restart(0, false);
        finish();
    }

    void begin_restart(uint32_t depth, bool resume) {
        m_work.restarts += 1;
        m_short.restart(depth, uint32_t(m_stack_size));
        m_resume = resume;
        plan_node(m_short.replay_node());
    }

    void replay_step() {
        // A revisit re-tests the node's child boxes to follow the trail; the walk is unchanged.
        m_work.restart_steps += 1;
        m_work.restart_box_tests += detail::popcount8(Codec::valid_mask(node(m_short.replay_node())));
        m_short.replay_advance();
        if (m_short.replaying()) plan_node(m_short.replay_node());
        else if (m_resume) plan_next();
        else finish();
    }

    /// The narrower test on every slot of `d` (node `n` decoded, against the same interval); the
    /// slots only it accepts (not in fp32_mask) are handed to m_rp when `enter`. Returns its hit
    /// mask. With quantised box tests (AQB8: Huang, Yang & Yeh, ISCA 2025) the hardware tests
    /// the node's 8-bit child boxes in integer arithmetic after quantising the ray into the
    /// node's grid; we take that test as exact on the child box grown by one grid cell per side
    /// (the ray's origin rounded outward to the grid), run in fp32 on the grown box: conservative,
    /// since the slab test is monotone in the box under rounding.
    uint32_t rp_tests(const Node& n, const DecodedNode& d, uint32_t fp32_mask, float tnear[kMaxWideWidth],
                      bool enter = true) {
        float cell[3];
        Codec::cell(n, cell);
        uint32_t mask = 0;
        for (uint32_t v = d.valid; v; v &= v - 1) {
            const int s = __builtin_ctz(v);
            float lo[3] = {d.lo[0][s], d.lo[1][s], d.lo[2][s]};
            float hi[3] = {d.hi[0][s], d.hi[1][s], d.hi[2][s]};
            bool hit;
            if (m_quantized) {
                for (int a = 0; a < 3; ++a) lo[a] -= cell[a], hi[a] += cell[a];
                hit = detail::box_kernel(m_box, lo, hi, m_ray.tmin, m_cull_t, &tnear[s]);
            } else {
                hit = intersect_box_rp(m_box, lo, hi, m_ray.tmin, m_cull_t, m_rp.bits(), &tnear[s]);
            }
            if (!hit) continue;
            mask |= 1u << s;
            if (enter && !(fp32_mask >> s & 1u)) m_work.rp_box_hits += 1, m_rp.enter(d.ref[s], d.count[s]);
        }
        return mask;
    }

    void rp_step() {
        // The extra walk tests with the narrower test alone; its leaves' fp32 triangle tests
        // cannot hit (rp_boxes.h), so they are counted, not run.
        const ReducedPrecisionBoxes::Entry e = m_rp.pop();
        if (e.count == 0) {
            DecodedNode d;
            Codec::decode(node(e.ref), d);
            m_work.rp_steps += 1;
            m_work.rp_box_tests += detail::popcount8(d.valid);
            float tnear[kMaxWideWidth];
            const uint32_t mask = rp_tests(node(e.ref), d, 0, tnear, false);
            for (uint32_t m = mask; m; m &= m - 1) m_rp.enter(d.ref[__builtin_ctz(m)], d.count[__builtin_ctz(m)]);
        } else {
            m_work.rp_tri_tests += e.count;
        }
        if (!m_rp.empty()) plan_at(m_rp.next().ref, m_rp.next().count);
        else m_plan = m_rp.resume();
    }

    void finish() {
        if (m_hit.prim < 0) m_hit = Hit{};
        m_plan.finish();
    }

    /// The reduced-precision shadow's bits when it runs quantised box tests (its walk, not its width).
    static constexpr uint32_t kQuantizedTestBits = 8;

    WideView m_view;
    AnyHitOrder m_anyhit_order;  ///< child order of any-hit rays (closest-hit: the view's order)
    bool m_quantized = false;  ///< quantised (integer) box tests drive the extra walk
    RayBoxPre m_box;
    RayTrianglePre m_tri;
    uint32_t m_octant = 0;
    float m_cull_t = 0.0f;
    uint32_t m_ref = 0;    ///< node index, or first triangle of a leaf
    uint32_t m_count = 0;  ///< 0: m_ref is a node; else the leaf's triangle count
    std::vector<WideStackEntry> m_stack;
    // Short stack only: the current node's depth, each entry's depth, and the shadow.
    uint32_t m_depth = 0;
    bool m_resume = false;  ///< after the re-descent: m_ref/m_count (true) or the end (false)
    std::vector<uint32_t> m_entry_depth;
    ShortStack m_short;
    // Reduced-precision boxes only: each entry's entry distance by the narrower test, and the shadow.
    std::vector<float> m_rp_tnear;
    ReducedPrecisionBoxes m_rp;
};

}  // namespace rtsim
