// The kd-tree's stepper (kd_stepper.h): the order of visits and the work counted here are the
// definition the SystemC model matches (docs/accel.md, "kdtree").
#include "traces/accel/kdtree/kd_stepper.h"

namespace rtsim {

void KdStepper::begin(const Ray& ray, TraversalMode mode) {
    begin_walk();
    if (start(ray, mode, m_view.node_count == 0)) m_phase = Phase::clip;
}

StepOutcome KdStepper::execute() {
    StepOutcome out;
    if (m_plan.done) return out;
    if (replaying()) return replay_step(), out;
    switch (m_phase) {
        case Phase::clip:
            clip(m_view.bounds);
            break;
        case Phase::node: {
            m_work.steps += 1;
            const KdNode& n = m_view.nodes[m_node];
            if (!n.leaf()) {
                interior(n);
            } else if (n.ref_count() == 0) {
                pop_next();
            } else {
                m_phase = Phase::list;
                open_list(m_view.list, n.first_ref(), n.ref_count());
            }
            break;
        }
        case Phase::list:
            if (!list_step(m_view.list, out)) pop_next();
            break;
    }
    return out;
}

void KdStepper::visit(uint32_t node, const detail::SlabInterval& cell) {
    m_node = node;
    m_cell = cell;
    m_phase = Phase::node;
    plan_node(node);
}

void KdStepper::plan_node(uint32_t node) {
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
    descend(m_node + 1, below, n.above(), above, negative);
}

}  // namespace rtsim
