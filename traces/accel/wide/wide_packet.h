#pragma once
// Packets on the wide BVHs (rules in wide_packet_kernel.h): the packet stepper the model's packet
// unit drives, and the fused packet loop the hit checker takes packet work from, for every codec
// (fp32 bvh4/6/8 and the compressed cwbvh6/8). Both share the kernel, so they agree on every
// ray's hit and work and on the packet's counts (tested, with the hits against single-ray
// traversal).
//
// A packet step fetches one node (Codec::kBytes: 128 to 256 bytes fp32, 64 or 80 compressed) and
// runs one box test per child and active ray (locality key: the node), or fetches a leaf's
// triangles once and runs one triangle test per triangle and active ray, plus the alpha tests
// the hits call for.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "traces/accel/stack_reads.h"
#include "traces/accel/wide/wide_packet_kernel.h"
#include "traces/accel/wide/wide_stepper.h"

namespace rtsim {

namespace detail {
/// A leaf's first triangle (null for a node).
inline const HwTriangle* leaf(const WideView& v, uint32_t ref, uint32_t count) {
    return count ? v.triangles + ref : nullptr;
}

/// The wide BVHs' single-ray rules for a ray walking alone on its lane (LaneWalker): those of
/// wide_stepper.h with a plain stack and fp32 box tests.
template <class Codec>
struct WideLaneRules {
    using Entry = WideStackEntry;
    WideView view;
    const typename Codec::Node& node(uint32_t i) const {
        return *reinterpret_cast<const typename Codec::Node*>(view.nodes + uint64_t(i) * Codec::kBytes);
    }
    bool descend(PacketLanes& p, uint32_t r, uint32_t* ref, uint32_t* count, std::vector<Entry>& stack,
                 int& size) const {
        DecodedNode d;
        Codec::decode(node(*ref), d);
        WorkCounts& w = p.work[r];
        w.steps += 1;
        w.box_tests += popcount8(d.valid);
        float tnear[kMaxWideWidth];
        const uint32_t mask = wide_box_tests(p.box[r], d, p.ray[r].tmin, p.cull[r], tnear);
        uint8_t slots[kMaxWideWidth];
        const int n = order_entered(mask, tnear, view.order, ray_octant(p.box[r]), d, p.order_of(r), slots);
        if (n == 0) return false;
        for (int i = n - 1; i >= 1; --i) {
            if (size_t(size) >= stack.size()) throw_wide_packet_overflow(stack.size());
            stack[size_t(size++)] = {d.ref[slots[i]], d.count[slots[i]], tnear[slots[i]]};
        }
        *ref = d.ref[slots[0]], *count = d.count[slots[0]];
        return true;
    }
    void plan(StepPlan& plan, uint32_t ref, uint32_t count) const {
        if (count == 0) {
            plan.reset(ref);
            plan.add_fetch(view.node_base + uint64_t(ref) * Codec::kBytes, Codec::kBytes, DataKind::node);
            plan.add_op(OpKind::box, popcount8(Codec::valid_mask(node(ref))));
        } else {
            plan.reset(kNoLocality);  // a leaf's triangles belong to its node's treelet
            const TriangleAddressing::Span span = view.tri_at.span(ref, count);
            plan.add_fetch(span.address, span.bytes, DataKind::triangle);
            const LeafTests t = leaf_tests(view.triangles + ref, count, view.curved);
            plan.add_leaf_ops(t);
        }
    }
    const HwTriangle* leaf(uint32_t ref) const { return view.triangles + ref; }
};
}  // namespace detail

template <class Codec>
class WidePacketStepper final : public PacketStepper {
public:
    explicit WidePacketStepper(const WideView& view)
        : m_view(view), m_stack(std::max<uint32_t>(1, view.max_stack)) {
        m_walk.stack.resize(m_stack.size());
    }

    void begin_packet(const Ray* rays, const TraversalMode* modes, uint32_t n) override {
        start_packet(rays, modes, n);
        m_split = false;
        if (m_active == 0 || m_view.node_count == 0) return finish();
        m_ref = 0;  // the root: every valid ray starts there
        m_count = 0;
        plan_next();
    }

    StepOutcome execute() override {
        StepOutcome out;
        if (m_plan.done) return out;
        DecodedNode d;
        if (m_count == 0) Codec::decode(node(m_ref), d);
        if (m_split) {
            bool more = false;
            out.add_op(OpKind::anyhit, m_walk.step(m_lanes, &d, m_view.order, detail::leaf(m_view, m_ref, m_count), m_stack,
                                                   &m_ref, &m_count, &more));
            if (more) plan_next();
            else finish();
            return out;
        }
        if (m_count == 0) {
            if (detail::wide_packet_descend(m_lanes, m_active, d, m_view.order, m_stack, m_stack_size, &m_ref,
                                            &m_count, &m_active))
                plan_next();
            else
                pop_next();
            return out;
        }
        out.add_op(OpKind::anyhit, detail::packet_leaf(m_lanes, m_active, m_view.triangles + m_ref, m_count));
        pop_next();
        return out;
    }
    Stepper& lane_walker(uint32_t i) override { return m_walkers[i]; }

    /// The packet's shared stack's top entries (none while a split packet's rays walk in turn).
    uint32_t stack_reads(Fetch* out, uint32_t max) const override {
        if (m_split) return 0;
        return tree_stack_reads(m_stack.data(), m_stack_size, m_view.node_base, Codec::kBytes, m_view.tri_at, out, max);
    }

private:
    using Node = typename Codec::Node;
    const Node& node(uint32_t i) const {
        return *reinterpret_cast<const Node*>(m_view.nodes + uint64_t(i) * Codec::kBytes);
    }

    void plan_next() {
        if (!m_split && m_count == 0 && detail::should_split(m_lanes, m_active, m_split_below)) {
            if (m_split_walks == SplitWalks::lanes) return launch_lanes();
            m_walk.begin(m_lanes, m_stack, m_stack_size, m_ref, m_count, m_active);
            m_split = true;
            ++m_counts.splits;
            if (!m_walk.next_ray(m_lanes, m_stack, &m_ref, &m_count)) return finish();
        }
        if (m_split) {
            // One ray's step: the frozen shared stack stays, the ray's own entries on top of it.
            m_active = lane_bit(m_walk.ray);
            m_stack_size = m_walk.frozen + m_walk.size;
            ++m_counts.split_steps;
        }
        const uint32_t rays = lane_count(m_active);
        m_counts.active_rays += rays;
        if (m_count == 0) {
            ++m_counts.node_steps;
            m_plan.reset(m_ref);
            m_plan.add_fetch(m_view.node_base + uint64_t(m_ref) * Codec::kBytes, Codec::kBytes, DataKind::node);
            m_plan.add_op(OpKind::box, detail::popcount8(Codec::valid_mask(node(m_ref))) * rays);
        } else {
            ++m_counts.leaf_steps;
            m_plan.reset(kNoLocality);  // a leaf's triangles belong to its node's treelet
            const TriangleAddressing::Span span = m_view.tri_at.span(m_ref, m_count);
            m_plan.add_fetch(span.address, span.bytes, DataKind::triangle);
            const detail::LeafTests t = detail::leaf_tests(m_view.triangles + m_ref, m_count, m_view.curved);
            m_plan.add_leaf_ops(t, rays);
        }
    }

    void launch_lanes() {
        ++m_counts.splits;
        if (m_walkers.empty())
            m_walkers.assign(kMaxPacketLanes, LaneWalker<detail::WideLaneRules<Codec>>(
                                                  detail::WideLaneRules<Codec>{m_view}, m_stack.size()));
        m_split_lanes = launch_lane_walks(m_lanes, m_counts, m_walkers, m_stack.data(), m_stack_size, m_active,
                                          m_ref, m_count);
        m_active = 0;
        m_stack_size = 0;
        m_plan.finish();
    }

    void pop_next() {
        if (m_lanes.live && detail::packet_pop(m_lanes, m_stack.data(), m_stack_size, &m_ref, &m_count, &m_active))
            return plan_next();
        finish();
    }

    void finish() { end_packet(); }

    WideView m_view;
    uint32_t m_ref = 0;    ///< node index, or first triangle of a leaf
    uint32_t m_count = 0;  ///< 0: m_ref is a node; else the leaf's triangle count
    bool m_split = false;  ///< the hybrid: the packet split, its rays walk alone (m_walk)
    std::vector<detail::PacketStackEntry> m_stack;
    detail::WideSplitWalk m_walk;
    std::vector<LaneWalker<detail::WideLaneRules<Codec>>> m_walkers;  ///< SplitWalks::lanes: one per lane
};

/// The fused packet loop: rays[0, n) traced as one packet; each ray's hit and work, and the
/// packet's counts (any of hits, work, counts may be null); `split_below` as
/// PacketStepper::set_split_below, `anyhit_order` as PacketStepper::set_anyhit_order.
template <class Codec>
void trace_packet_wide(const WideView& view, const Ray* rays, const TraversalMode* modes, uint32_t n, Hit* hits,
                       WorkCounts* work, PacketCounts* counts, float split_below,
                       AnyHitOrder anyhit_order = AnyHitOrder::nearest) {
    static thread_local PacketLanes p;
    static thread_local std::vector<detail::PacketStackEntry> stack;
    static thread_local detail::WideSplitWalk walk;
    const size_t depth = std::max<uint32_t>(1, view.max_stack);
    if (stack.size() != depth) stack.resize(depth), walk.stack.resize(depth);
    p.anyhit_order = anyhit_order;
    p.begin(rays, modes, n);
    PacketCounts c;
    LaneMask active = p.live;
    uint32_t ref = 0, count = 0;
    int size = 0;
    bool split = false;
    bool more = active != 0 && view.node_count != 0;
    DecodedNode d;
    auto node_at = [&](uint32_t i) {
        Codec::decode(*reinterpret_cast<const typename Codec::Node*>(view.nodes + uint64_t(i) * Codec::kBytes), d);
    };
    while (more) {
        if (!split && count == 0 && detail::should_split(p, active, split_below)) {
            walk.begin(p, stack, size, ref, count, active);
            split = true;
            ++c.splits;
            if (!walk.next_ray(p, stack, &ref, &count)) break;
        }
        c.active_rays += split ? 1 : lane_count(active);
        ++(count == 0 ? c.node_steps : c.leaf_steps);
        if (count == 0) node_at(ref);
        if (split) {
            ++c.split_steps;
            walk.step(p, &d, view.order, detail::leaf(view, ref, count), stack, &ref, &count, &more);
            continue;
        }
        if (count == 0) {
            if (detail::wide_packet_descend(p, active, d, view.order, stack, size, &ref, &count, &active)) continue;
        } else {
            detail::packet_leaf(p, active, view.triangles + ref, count);
        }
        more = p.live && detail::packet_pop(p, stack.data(), size, &ref, &count, &active);
    }
    p.finish();
    for (uint32_t i = 0; i < n; ++i) {
        if (hits) hits[i] = p.hit[i];
        if (work) work[i] = p.work[i];
    }
    if (counts) *counts = c;
}

}  // namespace rtsim
