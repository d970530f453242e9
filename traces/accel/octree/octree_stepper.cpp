// The octree's stepper (octree_stepper.h): the order of visits and the work counted here are the
// definition the SystemC model matches (docs/accel.md, "octree").
#include "traces/accel/octree/octree_stepper.h"

#include <utility>

#include "traces/common/error.h"

namespace rtsim {

void OctreeStepper::begin(const Ray& ray, TraversalMode mode) {
    if (!start(ray, mode, m_view.node_count == 0)) return;
    m_octant = 0;
    for (int a = 0; a < 3; ++a) {
        m_negative[a] = detail::slab_negative(m_box, a);
        m_octant |= uint32_t(m_negative[a]) << a;
    }
    m_phase = Phase::clip;
}

StepOutcome OctreeStepper::execute() {
    StepOutcome out;
    if (m_plan.done) return out;
    switch (m_phase) {
        case Phase::clip:
            clip();
            break;
        case Phase::node: {
            m_work.steps += 1;
            const OctNode& n = m_view.nodes[m_cell.node];
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

void OctreeStepper::clip() {
    m_work.box_tests += 1;
    Cell root{0, 0.0f, {}, {}};
    for (int a = 0; a < 3; ++a) {
        root.tlo[a] = detail::slab_distance(m_box, a, m_view.bounds.lo[a]);
        root.thi[a] = detail::slab_distance(m_box, a, m_view.bounds.hi[a]);
    }
    const detail::SlabInterval s = detail::slab_planes(root.tlo, root.thi, m_negative, m_ray.tmin);
    if (!detail::slab_hit(s, m_cull_t)) return finish();
    root.tn = s.tn;
    visit(root);
}

void OctreeStepper::visit(const Cell& cell) {
    m_cell = cell;
    m_phase = Phase::node;
    m_plan.reset(cell.node);
    m_plan.add_fetch(m_view.node_base + uint64_t(cell.node) * sizeof(OctNode), sizeof(OctNode), DataKind::node);
    if (!m_view.nodes[cell.node].leaf()) m_plan.add_op(OpKind::plane, 3);
}

void OctreeStepper::interior(const OctNode& n) {
    // Three ray/plane tests: the centre planes' distances; each child's six are then a choice.
    m_work.plane_tests += 3;
    float tm[3];
    for (int a = 0; a < 3; ++a) tm[a] = detail::slab_distance(m_box, a, n.centre(a));
    Cell hit[8];
    uint32_t order[8], count = 0;
    for (uint32_t c = 0; c < 8; ++c) {
        if (!(n.mask() >> c & 1u)) continue;
        Cell& k = hit[count];
        k.node = n.child(c);
        for (int a = 0; a < 3; ++a) {
            const bool upper = c >> a & 1u;
            k.tlo[a] = upper ? tm[a] : m_cell.tlo[a];
            k.thi[a] = upper ? m_cell.thi[a] : tm[a];
        }
        const detail::SlabInterval s = detail::slab_planes(k.tlo, k.thi, m_negative, m_ray.tmin);
        if (!detail::slab_hit(s, m_cull_t)) continue;
        k.tn = s.tn;
        order[count++] = c ^ m_octant;
    }
    // Nearest first; ties in the mirrored child order (the sequence Revelles' table follows).
    for (uint32_t i = 1; i < count; ++i)
        for (uint32_t j = i; j > 0 && (hit[j].tn < hit[j - 1].tn || (hit[j].tn == hit[j - 1].tn && order[j] < order[j - 1])); --j) {
            std::swap(hit[j], hit[j - 1]);
            std::swap(order[j], order[j - 1]);
        }
    if (count == 0) return pop_next();
    if (m_stack_size + int(count) - 1 > int(kOctMaxStack)) throw Error("octree traversal stack overflow");
    for (uint32_t i = count; i-- > 1;) m_stack[m_stack_size++] = hit[i];
    visit(hit[0]);
}

void OctreeStepper::pop_next() {
    while (m_stack_size > 0) {
        const Cell& c = m_stack[--m_stack_size];
        if (c.tn > m_cull_t) continue;  // entered beyond the best hit: dropped without a fetch
        return visit(c);
    }
    finish();
}

}  // namespace rtsim
