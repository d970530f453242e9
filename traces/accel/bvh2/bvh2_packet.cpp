// The binary BVH's packet stepper and fused packet loop (bvh2_packet.h): the same node, leaf,
// pop and split rules (bvh2_packet_kernel.h), one driven step by step, one in a loop.
#include "traces/accel/bvh2/bvh2_packet.h"

#include "traces/accel/stack_reads.h"

namespace rtsim {

void Bvh2PacketStepper::begin_packet(const Ray* rays, const TraversalMode* modes, uint32_t n) {
    start_packet(rays, modes, n);
    m_split = false;
    if (m_active == 0 || m_view.node_count == 0) return finish();
    m_ref = 0;  // the root: every valid ray starts there
    m_count = 0;
    plan_next();
}

void detail::Bvh2LaneRules::plan(StepPlan& plan, uint32_t ref, uint32_t count) const {
    if (count == 0) {
        plan.reset(ref);
        plan.add_fetch(view.node_base + uint64_t(ref) * sizeof(HwNode), sizeof(HwNode), DataKind::node);
        if (view.oriented(ref)) plan.add_op(OpKind::obb, 1);
        plan.add_op(OpKind::box, 2);
    } else {
        plan.reset(kNoLocality);  // a leaf's triangles belong to its node's treelet
        const TriangleAddressing::Span span = view.tri_at.span(ref, count);
        plan.add_fetch(span.address, span.bytes, DataKind::triangle);
        const detail::LeafTests t = detail::leaf_tests(view.triangles + ref, count, view.curved);
        plan.add_leaf_ops(t);
    }
}

uint32_t Bvh2PacketStepper::stack_reads(Fetch* out, uint32_t max) const {
    if (m_split) return 0;
    return tree_stack_reads(m_stack, m_stack_size, m_view.node_base, uint32_t(sizeof(HwNode)), m_view.tri_at, out, max);
}

void Bvh2PacketStepper::launch_lanes() {
    ++m_counts.splits;
    if (m_walkers.empty())
        m_walkers.assign(kMaxPacketLanes, LaneWalker<detail::Bvh2LaneRules>(detail::Bvh2LaneRules{m_view},
                                                                           size_t(kTraversalStackSize)));
    m_split_lanes =
        launch_lane_walks(m_lanes, m_counts, m_walkers, m_stack, m_stack_size, m_active, m_ref, m_count);
    m_active = 0;
    m_stack_size = 0;
    m_plan.finish();
}

void Bvh2PacketStepper::plan_next() {
    if (!m_split && m_count == 0 && detail::should_split(m_lanes, m_active, m_split_below)) {
        if (m_split_walks == SplitWalks::lanes) return launch_lanes();
        detail::begin_split(m_lanes, m_stack, m_stack_size, m_ref, m_count, m_active, m_walk);
        m_split = true;
        ++m_counts.splits;
        if (!detail::split_next_ray(m_lanes, m_stack, m_walk, &m_ref, &m_count)) return finish();
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
        m_plan.add_fetch(m_view.node_base + uint64_t(m_ref) * sizeof(HwNode), sizeof(HwNode), DataKind::node);
        if (m_view.oriented(m_ref)) m_plan.add_op(OpKind::obb, rays);  // each ray rotated first
        m_plan.add_op(OpKind::box, 2 * rays);
    } else {
        ++m_counts.leaf_steps;
        m_plan.reset(kNoLocality);  // a leaf's triangles belong to its node's treelet
        const TriangleAddressing::Span span = m_view.tri_at.span(m_ref, m_count);
        m_plan.add_fetch(span.address, span.bytes, DataKind::triangle);
        const detail::LeafTests t = detail::leaf_tests(m_view.triangles + m_ref, m_count, m_view.curved);
        m_plan.add_leaf_ops(t, rays);
    }
}

StepOutcome Bvh2PacketStepper::execute() {
    StepOutcome out;
    if (m_plan.done) return out;
    if (m_split) {
        bool more = false;
        out.add_op(OpKind::anyhit, detail::split_step(m_lanes, m_view, m_stack, m_walk, &m_ref, &m_count, &more));
        if (more) plan_next();
        else finish();
        return out;
    }
    if (m_count == 0) {
        if (detail::packet_descend(m_lanes, m_active, m_view, m_ref, m_stack, m_stack_size, &m_ref, &m_count,
                                   &m_active))
            plan_next();
        else
            pop_next();
        return out;
    }
    out.add_op(OpKind::anyhit, detail::packet_leaf(m_lanes, m_active, m_view.triangles + m_ref, m_count));
    pop_next();
    return out;
}

void Bvh2PacketStepper::pop_next() {
    if (m_lanes.live && detail::packet_pop(m_lanes, m_stack, m_stack_size, &m_ref, &m_count, &m_active)) {
        plan_next();
        return;
    }
    finish();
}

void Bvh2PacketStepper::finish() { end_packet(); }

std::unique_ptr<PacketStepper> make_bvh2_packet_stepper(const Bvh2View& view, AnyHitOrder anyhit_order) {
    auto s = std::make_unique<Bvh2PacketStepper>(view);
    s->set_anyhit_order(anyhit_order);
    return s;
}

void trace_packet_bvh2(const Bvh2View& bvh, const Ray* rays, const TraversalMode* modes, uint32_t n, Hit* hits,
                       WorkCounts* work, PacketCounts* counts, float split_below, AnyHitOrder anyhit_order) {
    static thread_local PacketLanes p;
    static thread_local detail::PacketStackEntry stack[kTraversalStackSize];
    static thread_local detail::SplitWalk walk;
    p.anyhit_order = anyhit_order;
    p.begin(rays, modes, n);
    PacketCounts c;
    LaneMask active = p.live;
    uint32_t ref = 0, count = 0;
    int size = 0;
    bool split = false;
    bool more = active != 0 && bvh.node_count != 0;
    while (more) {
        if (!split && count == 0 && detail::should_split(p, active, split_below)) {
            detail::begin_split(p, stack, size, ref, count, active, walk);
            split = true;
            ++c.splits;
            if (!detail::split_next_ray(p, stack, walk, &ref, &count)) break;
        }
        c.active_rays += split ? 1 : lane_count(active);
        ++(count == 0 ? c.node_steps : c.leaf_steps);
        if (split) {
            ++c.split_steps;
            detail::split_step(p, bvh, stack, walk, &ref, &count, &more);
            continue;
        }
        if (count == 0) {
            if (detail::packet_descend(p, active, bvh, ref, stack, size, &ref, &count, &active)) continue;
        } else {
            detail::packet_leaf(p, active, bvh.triangles + ref, count);
        }
        more = p.live && detail::packet_pop(p, stack, size, &ref, &count, &active);
    }
    p.finish();
    for (uint32_t i = 0; i < n; ++i) {
        if (hits) hits[i] = p.hit[i];
        if (work) work[i] = p.work[i];
    }
    if (counts) *counts = c;
}

}  // namespace rtsim
