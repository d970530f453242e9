// The BIH's stepper (bih_stepper.h): the order of visits and the work counted here are the
// definition the SystemC model matches (docs/accel.md, "bih").
#include "traces/accel/bih/bih_stepper.h"

#include "traces/common/error.h"
#include "traces/isect/leaf_kernel.h"

namespace rtsim {

void BihStepper::begin(const Ray& ray, TraversalMode mode) {
    m_ray = ray;
    m_mode = mode;
    m_hit = Hit{};
    m_work = WorkCounts{};
    m_stack_size = 0;
    if (!ray_is_valid(ray) || m_view.node_count == 0) return finish();
    m_box = ray_box_precompute(ray);
    m_tri = ray_triangle_precompute(ray);
    m_hit.t = ray.tmax;  // the current best distance while traversing
    m_cull_t = detail::cull_distance(ray.tmax);
    m_phase = Phase::clip;
    m_plan.reset(kNoLocality);
    m_plan.add_op(OpKind::box, 1);
}

StepOutcome BihStepper::execute() {
    StepOutcome out;
    if (m_plan.done) return out;
    switch (m_phase) {
        case Phase::clip:
            clip();
            break;
        case Phase::node: {
            m_work.steps += 1;
            const BihNode& n = m_view.nodes[m_node];
            if (!n.leaf()) {
                interior(n);
            } else if (n.count() == 0) {
                pop_next();
            } else {
                m_phase = Phase::leaf;
                m_plan.reset(kNoLocality);  // a leaf's triangles belong to its node's treelet
                const TriangleAddressing::Span s = m_view.tri_at.span(n.first(), n.count());
                m_plan.add_fetch(s.address, s.bytes, DataKind::triangle);
                m_plan.add_op(OpKind::triangle, n.count());
            }
            break;
        }
        case Phase::leaf:
            out.add_op(OpKind::anyhit, leaf());
            break;
    }
    return out;
}

void BihStepper::clip() {
    m_work.box_tests += 1;
    const float lo[3] = {m_view.bounds.lo.x, m_view.bounds.lo.y, m_view.bounds.lo.z};
    const float hi[3] = {m_view.bounds.hi.x, m_view.bounds.hi.y, m_view.bounds.hi.z};
    const detail::SlabInterval cell = detail::slab_box(m_box, lo, hi, m_ray.tmin);
    if (!detail::slab_hit(cell, m_cull_t)) return finish();
    visit(0, cell);
}

void BihStepper::visit(uint32_t node, const detail::SlabInterval& cell) {
    m_node = node;
    m_cell = cell;
    m_phase = Phase::node;
    m_plan.reset(node);
    m_plan.add_fetch(m_view.node_base + uint64_t(node) * sizeof(BihNode), sizeof(BihNode), DataKind::node);
    if (!m_view.nodes[node].leaf()) m_plan.add_op(OpKind::plane, 2);
}

void BihStepper::interior(const BihNode& n) {
    // Two ray/plane tests: the left child's cell ends at clip[0], the right child's starts at clip[1].
    m_work.plane_tests += 2;
    const int axis = n.axis();
    const bool negative = detail::slab_negative(m_box, axis);
    const detail::SlabInterval left =
        detail::slab_below(m_cell, detail::slab_distance(m_box, axis, n.clip(0)), negative);
    const detail::SlabInterval right =
        detail::slab_above(m_cell, detail::slab_distance(m_box, axis, n.clip(1)), negative);
    const uint32_t left_node = n.left(), right_node = n.left() + 1;
    const detail::SlabInterval& near_cell = negative ? right : left;
    const detail::SlabInterval& far_cell = negative ? left : right;
    const uint32_t near_node = negative ? right_node : left_node, far_node = negative ? left_node : right_node;
    const bool near_hit = detail::slab_hit(near_cell, m_cull_t), far_hit = detail::slab_hit(far_cell, m_cull_t);
    if (near_hit && far_hit) {
        if (m_stack_size >= int(kBihMaxDepth)) throw Error("BIH traversal stack overflow (deeper than its image said)");
        m_stack[m_stack_size++] = Entry{far_node, far_cell};
    }
    if (near_hit) return visit(near_node, near_cell);
    if (far_hit) return visit(far_node, far_cell);
    pop_next();
}

uint32_t BihStepper::leaf() {
    const BihNode& n = m_view.nodes[m_node];
    m_work.tri_tests += n.count();
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

void BihStepper::pop_next() {
    while (m_stack_size > 0) {
        const Entry& e = m_stack[--m_stack_size];
        if (e.cell.tn > m_cull_t) continue;  // entered beyond the best hit: dropped without a fetch
        return visit(e.node, e.cell);
    }
    finish();
}

void BihStepper::finish() {
    if (m_hit.prim < 0) m_hit = Hit{};
    m_plan.finish();
}

}  // namespace rtsim
