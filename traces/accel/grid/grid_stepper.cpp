// The uniform grid's stepper (grid_stepper.h): the order of visits and the work counted here are
// the definition the SystemC model matches (docs/accel.md, "grid").
#include "traces/accel/grid/grid_stepper.h"

#include "traces/isect/ray_box_kernel.h"

namespace rtsim {

void GridStepper::begin(const Ray& ray, TraversalMode mode) {
    m_mailbox.clear();
    if (start(ray, mode, m_view.cell_count == 0)) m_phase = Phase::clip;
}

StepOutcome GridStepper::execute() {
    StepOutcome out;
    if (m_plan.done) return out;
    switch (m_phase) {
        case Phase::clip:
            clip();
            break;
        case Phase::cell: {
            m_work.steps += 1;
            m_work.cell_steps += 1;
            const GridCell& c = m_view.cells[m_cell];
            if (c.ref_count == 0) {
                next_cell();
                break;
            }
            m_phase = Phase::refs;
            m_list.plan_list(m_view.list, c.first_ref, c.ref_count, m_plan);  // belongs to its cell's brick
            break;
        }
        case Phase::refs:
            m_list.list_fetched(m_work);
            m_phase = Phase::triangles;
            next_batch();
            break;
        case Phase::triangles: {
            bool done = false;
            out.add_op(OpKind::anyhit, test_refs(m_list, m_view.list, m_mailbox, &done));
            if (done) finish();
            else next_batch();
            break;
        }
    }
    return out;
}

void GridStepper::clip() {
    m_work.box_tests += 1;
    const Aabb b = m_view.geometry.bounds();
    const float lo[3] = {b.lo.x, b.lo.y, b.lo.z}, hi[3] = {b.hi.x, b.hi.y, b.hi.z};
    float t0;
    if (!detail::box_kernel(m_box, lo, hi, m_ray.tmin, m_cull_t, &t0)) return finish();
    m_dda.begin(m_view.geometry, m_box, t0);
    next_cell();
}

void GridStepper::next_cell() {
    if (!m_dda.next(m_cull_t, &m_cell)) return finish();
    m_phase = Phase::cell;
    m_plan.reset(m_cell);
    m_plan.add_fetch(m_view.cell_base + uint64_t(m_cell) * sizeof(GridCell), sizeof(GridCell), DataKind::cell);
    m_plan.add_op(OpKind::cell, 1);
}

void GridStepper::next_batch() {
    if (!m_list.plan_batch(m_view.list, m_mailbox, m_work, m_plan)) next_cell();
}

}  // namespace rtsim
