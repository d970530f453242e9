// The B-Kd tree's stepper (bkd_stepper.h): the order of visits and the work counted here are the
// definition the SystemC model matches (docs/accel.md, "bkd").
#include "traces/accel/bkd/bkd_stepper.h"

#include "traces/isect/leaf_kernel.h"

namespace rtsim {

void BkdStepper::begin(const Ray& ray, TraversalMode mode) {
    if (start(ray, mode, m_view.node_count == 0)) m_phase = Phase::clip;
}

StepOutcome BkdStepper::execute() {
    StepOutcome out;
    if (m_plan.done) return out;
    switch (m_phase) {
        case Phase::clip:
            clip(m_view.bounds);
            break;
        case Phase::node: {
            m_work.steps += 1;
            const BkdNode& n = m_view.nodes[m_node];
            if (!n.leaf()) {
                interior(n);
            } else if (n.count() == 0) {
                pop_next();
            } else {
                m_phase = Phase::leaf;
                m_plan.reset(kNoLocality);  // a leaf's triangles belong to its node's treelet
                const TriangleAddressing::Span s = m_view.tri_at.span(n.first(), n.count());
                m_plan.add_fetch(s.address, s.bytes, DataKind::triangle);
                m_plan.add_leaf_ops(detail::leaf_tests(m_view.triangles + n.first(), n.count(), m_view.curved));
            }
            break;
        }
        case Phase::leaf:
            out.add_op(OpKind::anyhit, leaf());
            break;
    }
    return out;
}

void BkdStepper::visit(uint32_t node, const detail::SlabInterval& cell) {
    m_node = node;
    m_cell = cell;
    m_phase = Phase::node;
    plan_node(node);
}

void BkdStepper::plan_node(uint32_t node) {
    m_plan.reset(node);
    m_plan.add_fetch(m_view.node_base + uint64_t(node) * sizeof(BkdNode), sizeof(BkdNode), DataKind::node);
    if (!m_view.nodes[node].leaf()) m_plan.add_op(OpKind::plane, kNodeTests);
}

void BkdStepper::interior(const BkdNode& n) {
    // Four ray/plane tests: each child's cell is its parent's cut to [lo, hi] on the node's axis.
    m_work.plane_tests += kNodeTests;
    const int axis = n.axis();
    const bool negative = detail::slab_negative(m_box, axis);
    auto child = [&](int side) {
        const detail::SlabInterval below =
            detail::slab_below(m_cell, detail::slab_distance(m_box, axis, n.bound(side, 1)), negative);
        return detail::slab_above(below, detail::slab_distance(m_box, axis, n.bound(side, 0)), negative);
    };
    descend(n.left(), child(0), n.left() + 1, child(1), negative);
}

uint32_t BkdStepper::leaf() {
    const BkdNode& n = m_view.nodes[m_node];
    detail::count_leaf_tests(m_work, detail::leaf_tests(m_view.triangles + n.first(), n.count(), m_view.curved));
    const uint32_t alpha_before = m_work.anyhit_calls;
    const HwTriangle* tris = m_view.triangles + n.first();
    const bool done = m_mode == TraversalMode::any_hit
                          ? detail::leaf_step<true>(m_tri, m_ray.tmin, m_ray.tmax, tris, n.count(), m_hit, m_cull_t,
                                                    m_work.anyhit_calls)
                          : detail::leaf_step<false>(m_tri, m_ray.tmin, m_ray.tmax, tris, n.count(), m_hit, m_cull_t,
                                                     m_work.anyhit_calls);
    if (done) finish();
    else pop_next();
    return m_work.anyhit_calls - alpha_before;
}

}  // namespace rtsim
