// The binary BVH stepper (bvh2_stepper.h). The order of visits and the work counted here are the
// definition the SystemC model matches (docs/intersection.md); bvh2_trace.cpp fuses the same
// steps into one loop.
#include "traces/accel/bvh2/bvh2_stepper.h"

#include <string>

#include "traces/accel/stack_reads.h"
#include "traces/common/error.h"
#include "traces/isect/ray_box_rp.h"

namespace rtsim {

using detail::cull_distance;

namespace {

/// Child c's box of a binary node, per axis.
void child_box(const HwNode& node, int c, float lo[3], float hi[3]) {
    for (int a = 0; a < 3; ++a) lo[a] = node.lo(c, a), hi[a] = node.hi(c, a);
}

}  // namespace

namespace detail {

void throw_stack_overflow() {
    throw Error("traversal stack overflow (" + std::to_string(kTraversalStackSize) +
                " entries): BVH deeper than the builder's max_depth allows");
}

}  // namespace detail

void Bvh2Stepper::begin(const Ray& ray, TraversalMode mode) {
    m_ray = ray;
    m_mode = mode;
    m_hit = Hit{};
    m_work = WorkCounts{};
    m_stack_size = 0;
    m_depth = 0;
    m_short.begin();
    m_rp.begin();
    if (!ray_is_valid(ray) || m_view.node_count == 0) {
        finish();
        return;
    }
    m_box = ray_box_precompute(ray);
    m_tri = ray_triangle_precompute(ray);
    // While traversing, m_hit.t is the current best distance (the shrinking tmax).
    m_hit.t = ray.tmax;
    m_cull_t = cull_distance(ray.tmax);
    if (m_view.rotations) m_obb_pad = obb_pad(ray.origin, m_view.scene_radius);
    m_ref = 0;
    m_count = 0;
    plan_next();
}

void Bvh2Stepper::plan_at(uint32_t ref, uint32_t count) {
    // The host's copy of the data this step reads is prefetched now (traces/common/prefetch.h;
    // the node load was the model's largest stall).
    if (count == 0) {
        m_plan.reset(ref);
        m_plan.set_host(&m_view.nodes[ref], sizeof(HwNode));
        m_plan.add_fetch(m_view.node_base + uint64_t(ref) * sizeof(HwNode), sizeof(HwNode), DataKind::node);
        if (m_view.oriented(ref)) m_plan.add_op(OpKind::obb, 1);
        m_plan.add_op(OpKind::box, 2);
    } else {
        m_plan.reset(kNoLocality);  // a leaf's triangles belong to its node's treelet
        m_plan.set_host(m_view.triangles + ref, uint32_t(sizeof(HwTriangle) * count));
        const TriangleAddressing::Span s = m_view.tri_at.span(ref, count);
        m_plan.add_fetch(s.address, s.bytes, DataKind::triangle);
        const detail::LeafTests t = detail::leaf_tests(m_view.triangles + ref, count, m_view.curved);
        m_plan.add_leaf_ops(t);
    }
}

StepOutcome Bvh2Stepper::execute() {
    StepOutcome out;
    if (m_plan.done) return out;
    if (m_rp.walking()) {
        rp_step();
        return out;
    }
    if (m_short.replaying()) {
        replay_step();
    } else if (m_count == 0) {
        visit_node(m_view.nodes[m_ref]);
    } else {
        out.add_op(OpKind::anyhit, visit_leaf(m_view.triangles + m_ref));
    }
    // Boxes only the reduced-precision test entered are walked before the step just planned.
    if (m_rp.pending()) {
        m_rp.start(m_plan);
        plan_at(m_rp.next().ref, m_rp.next().count);
    }
    return out;
}

uint32_t Bvh2Stepper::stack_reads(Fetch* out, uint32_t max) const {
    return tree_stack_reads(m_stack, m_stack_size, m_view.node_base, uint32_t(sizeof(HwNode)), m_view.tri_at, out, max);
}

void Bvh2Stepper::visit_node(const HwNode& node) {
    // Nearer child next (child 0 on equal entry distances; any-hit rays by their order); the other pushed.
    const int before = m_stack_size;
    if (m_short.enabled()) m_short.visit(m_ref, m_depth);
    // An oriented node is tested by the ray rotated into its frame, against its widened boxes.
    const bool oriented = m_view.oriented(m_ref);
    detail::OrientedNode o;  // filled at an oriented node only (no zeroing on the hot path)
    if (oriented) {
        m_work.obb_rotations += 1;
        o = detail::oriented_node(m_view, m_ref, m_ray, m_obb_pad);
    }
    const RayBoxPre& pre = oriented ? o.pre : m_box;
    const HwNode& tested = oriented ? o.node : node;
    float rp_tnear[2];
    if (m_rp.enabled()) rp_tests(tested, pre, rp_tnear);
    const AnyHitOrder order = m_mode == TraversalMode::any_hit ? m_anyhit_order : AnyHitOrder::nearest;
    const bool entered =
        detail::descend(pre, tested, m_ray.tmin, m_cull_t, m_work, m_stack, m_stack_size, &m_ref, &m_count, order);
    if (!entered) return pop_next();
    if (m_rp.enabled() && m_stack_size > before) {
        const detail::Bvh2StackEntry& pushed = m_stack[m_stack_size - 1];
        const int slot = pushed.ref == node.child_ref[0] && pushed.count == node.child_count[0] ? 0 : 1;
        m_rp_tnear[m_stack_size - 1] = rp_tnear[slot];
    }
    if (m_short.enabled()) {
        if (m_stack_size > before) {
            m_entry_depth[m_stack_size - 1] = m_depth + 1;
            if (m_short.push()) m_work.stack_drops += 1;
        }
        m_depth += 1;
    }
    plan_next();
}

uint32_t Bvh2Stepper::visit_leaf(const HwTriangle* triangles) {
    const detail::LeafTests t = detail::leaf_tests(triangles, m_count, m_view.curved);
    detail::count_leaf_tests(m_work, t);
    const uint32_t alpha_before = m_work.anyhit_calls;
    const bool done =
        m_mode == TraversalMode::any_hit
            ? detail::leaf_step<true>(m_tri, m_ray.tmin, m_ray.tmax, triangles, m_count, m_hit, m_cull_t,
                                      m_work.anyhit_calls)
            : detail::leaf_step<false>(m_tri, m_ray.tmin, m_ray.tmax, triangles, m_count, m_hit, m_cull_t,
                                       m_work.anyhit_calls);
    if (done) finish();
    else pop_next();
    return m_work.anyhit_calls - alpha_before;
}

void Bvh2Stepper::pop_next() {
    // Entries entered beyond the (widened) best hit are dropped without a fetch. With a short
    // stack, reaching an entry it dropped means a restart (short_stack.h).
    bool restart = false;
    while (m_stack_size > 0) {
        const detail::Bvh2StackEntry& e = m_stack[--m_stack_size];
        if (m_short.enabled()) restart |= m_short.pop();
        if (e.tnear > m_cull_t) {
            // The narrower test's entry distance may be near enough: the hardware visits it.
            if (m_rp.enabled() && m_rp_tnear[m_stack_size] <= m_cull_t) {
                m_work.rp_box_hits += 1;
                m_rp.enter(e.ref, e.count);
            }
            continue;
        }
        m_ref = e.ref;
        m_count = e.count;
        if (m_short.enabled()) m_depth = m_entry_depth[m_stack_size];
        if (restart) return begin_restart(m_depth, true);
        plan_next();
        return;
    }
    if (restart) return begin_restart(0, false);
    finish();
}

void Bvh2Stepper::begin_restart(uint32_t depth, bool resume) {
    m_work.restarts += 1;
    m_short.restart(depth, uint32_t(m_stack_size));
    m_resume = resume;
    plan_replay();
}

void Bvh2Stepper::plan_replay() {
    const uint32_t node = m_short.replay_node();
    m_plan.reset(node);
    m_plan.add_fetch(m_view.node_base + uint64_t(node) * sizeof(HwNode), sizeof(HwNode), DataKind::node);
    if (m_view.oriented(node)) m_plan.add_op(OpKind::obb, 1);  // the ray rotated to re-test its boxes
    m_plan.add_op(OpKind::box, 2);
}

void Bvh2Stepper::replay_step() {
    // A revisit re-tests the node's child boxes to follow the trail; the walk's state is unchanged.
    m_work.restart_steps += 1;
    m_work.restart_box_tests += 2;
    if (m_view.oriented(m_short.replay_node())) m_work.obb_rotations += 1;
    m_short.replay_advance();
    if (m_short.replaying()) plan_replay();
    else if (m_resume) plan_next();
    else finish();
}

void Bvh2Stepper::rp_tests(const HwNode& node, const RayBoxPre& pre, float tnear[2]) {
    for (int c = 0; c < 2; ++c) {
        if (node.child_count[c] == kEmptyChild) continue;
        float lo[3], hi[3];
        child_box(node, c, lo, hi);
        float t32 = 0.0f;  // the fp32 test is the node kernel's arithmetic (ray_box_kernel.h)
        const bool fp32 = detail::box_kernel(pre, lo, hi, m_ray.tmin, m_cull_t, &t32);
        if (intersect_box_rp(pre, lo, hi, m_ray.tmin, m_cull_t, m_rp.bits(), &tnear[c]) && !fp32) {
            m_work.rp_box_hits += 1;
            m_rp.enter(node.child_ref[c], node.child_count[c]);
        }
    }
}

void Bvh2Stepper::rp_step() {
    // The extra walk tests with the narrower test alone; its leaves' fp32 triangle tests cannot
    // hit (rp_boxes.h), so they are counted, not run.
    const ReducedPrecisionBoxes::Entry e = m_rp.pop();
    if (e.count == 0) {
        const bool oriented = m_view.oriented(e.ref);
        detail::OrientedNode o;  // filled at an oriented node only (no zeroing on the hot path)
        if (oriented) {
            m_work.obb_rotations += 1;  // its plan rotates the ray too (plan_at)
            o = detail::oriented_node(m_view, e.ref, m_ray, m_obb_pad);
        }
        const HwNode& node = oriented ? o.node : m_view.nodes[e.ref];
        const RayBoxPre& pre = oriented ? o.pre : m_box;
        m_work.rp_steps += 1;
        m_work.rp_box_tests += 2;
        for (int c = 0; c < 2; ++c) {
            if (node.child_count[c] == kEmptyChild) continue;
            float lo[3], hi[3];
            child_box(node, c, lo, hi);
            float t = 0.0f;
            if (intersect_box_rp(pre, lo, hi, m_ray.tmin, m_cull_t, m_rp.bits(), &t))
                m_rp.enter(node.child_ref[c], node.child_count[c]);
        }
    } else {
        m_work.rp_tri_tests += e.count;
    }
    if (!m_rp.empty()) plan_at(m_rp.next().ref, m_rp.next().count);
    else m_plan = m_rp.resume();
}

void Bvh2Stepper::finish() {
    if (m_hit.prim < 0) m_hit = Hit{};
    m_plan.finish();
}

}  // namespace rtsim
