// The kd-tree's stepper (kd_stepper.h): the order of visits and the work counted here are the
// definition the SystemC model matches (docs/accel.md, "kdtree").
#include "traces/accel/kdtree/kd_stepper.h"

#include "traces/common/error.h"
#include "traces/isect/leaf_kernel.h"

namespace rtsim {

void KdStepper::begin(const Ray& ray, TraversalMode mode) {
    m_ray = ray;
    m_mode = mode;
    m_hit = Hit{};
    m_work = WorkCounts{};
    m_stack_size = 0;
    m_mailbox.clear();
    if (!ray_is_valid(ray) || m_view.node_count == 0) return finish();
    m_box = ray_box_precompute(ray);
    m_tri = ray_triangle_precompute(ray);
    m_hit.t = ray.tmax;  // the current best distance while traversing
    m_cull_t = detail::cull_distance(ray.tmax);
    m_phase = Phase::clip;
    m_plan.reset(kNoLocality);
    m_plan.add_op(OpKind::box, 1);
}

StepOutcome KdStepper::execute() {
    StepOutcome out;
    if (m_plan.done) return out;
    switch (m_phase) {
        case Phase::clip:
            clip();
            break;
        case Phase::node: {
            m_work.steps += 1;
            const KdNode& n = m_view.nodes[m_node];
            if (!n.leaf()) {
                interior(n);
            } else if (n.ref_count() == 0) {
                pop_next();
            } else {
                m_phase = Phase::refs;
                m_list.plan_list(m_view.list, n.first_ref(), n.ref_count(), m_plan);
            }
            break;
        }
        case Phase::refs:
            m_list.list_fetched(m_work);
            m_phase = Phase::triangles;
            next_batch();
            break;
        case Phase::triangles: {
            bool done = false;
            const uint32_t alpha =
                m_mode == TraversalMode::any_hit
                    ? m_list.test_batch<true>(m_view.list, m_tri, m_ray.tmin, m_ray.tmax, m_hit, m_cull_t, m_mailbox,
                                              m_work, &done)
                    : m_list.test_batch<false>(m_view.list, m_tri, m_ray.tmin, m_ray.tmax, m_hit, m_cull_t, m_mailbox,
                                               m_work, &done);
            out.add_op(OpKind::anyhit, alpha);
            if (done) finish();
            else next_batch();
            break;
        }
    }
    return out;
}

void KdStepper::clip() {
    m_work.box_tests += 1;
    const float lo[3] = {m_view.bounds.lo.x, m_view.bounds.lo.y, m_view.bounds.lo.z};
    const float hi[3] = {m_view.bounds.hi.x, m_view.bounds.hi.y, m_view.bounds.hi.z};
    const detail::SlabInterval cell = detail::slab_box(m_box, lo, hi, m_ray.tmin);
    if (!detail::slab_hit(cell, m_cull_t)) return finish();
    visit(0, cell);
}

void KdStepper::visit(uint32_t node, const detail::SlabInterval& cell) {
    m_node = node;
    m_cell = cell;
    m_phase = Phase::node;
    m_plan.reset(node);
    m_plan.add_fetch(m_view.node_base + uint64_t(node) * sizeof(KdNode), sizeof(KdNode), DataKind::node);
    if (!m_view.nodes[node].leaf()) m_plan.add_op(OpKind::plane, 1);
}

void KdStepper::interior(const KdNode& n) {
    // One ray/plane test: the split plane's distance cuts the cell's interval in two.
    m_work.plane_tests += 1;
    const int axis = n.axis();
    const bool negative = detail::slab_negative(m_box, axis);
    const float t = detail::slab_distance(m_box, axis, n.split());
    const detail::SlabInterval below = detail::slab_below(m_cell, t, negative);
    const detail::SlabInterval above = detail::slab_above(m_cell, t, negative);
    // The near child is the one the ray enters first: below when it runs up the axis.
    const uint32_t below_node = m_node + 1, above_node = n.above();
    const detail::SlabInterval& near_cell = negative ? above : below;
    const detail::SlabInterval& far_cell = negative ? below : above;
    const uint32_t near_node = negative ? above_node : below_node, far_node = negative ? below_node : above_node;
    const bool near_hit = detail::slab_hit(near_cell, m_cull_t), far_hit = detail::slab_hit(far_cell, m_cull_t);
    if (near_hit && far_hit) {
        if (m_stack_size >= int(kKdMaxDepth)) throw Error("kd-tree traversal stack overflow (deeper than its image said)");
        m_stack[m_stack_size++] = Entry{far_node, far_cell};
    }
    if (near_hit) return visit(near_node, near_cell);
    if (far_hit) return visit(far_node, far_cell);
    pop_next();
}

void KdStepper::next_batch() {
    if (!m_list.plan_batch(m_view.list, m_mailbox, m_work, m_plan)) pop_next();
}

void KdStepper::pop_next() {
    // Pending cells lie behind the current one: those entered beyond the best hit are dropped.
    while (m_stack_size > 0) {
        const Entry& e = m_stack[--m_stack_size];
        if (e.cell.tn > m_cull_t) continue;
        return visit(e.node, e.cell);
    }
    finish();
}

void KdStepper::finish() {
    if (m_hit.prim < 0) m_hit = Hit{};
    m_plan.finish();
}

}  // namespace rtsim
