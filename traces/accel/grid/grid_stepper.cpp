// The uniform grid's stepper (grid_stepper.h): the order of visits and the work counted here are
// the definition the SystemC model matches (docs/accel.md, "grid").
#include "traces/accel/grid/grid_stepper.h"

#include "traces/isect/ray_box_kernel.h"

namespace rtsim {

void GridStepper::begin(const Ray& ray, TraversalMode mode) {
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
            m_phase = Phase::list;
            open_list(m_view.list, c.first_ref, c.ref_count);  // belongs to its cell's brick
            break;
        }
        case Phase::list:
            if (!list_step(m_view.list, out)) next_cell();
            break;
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

}  // namespace rtsim
