// The space-partitioning steppers' shared steps (cell_stepper.h).
#include "traces/accel/cell_stepper.h"

#include "traces/isect/leaf_kernel.h"

namespace rtsim {

bool CellStepper::start(const Ray& ray, TraversalMode mode, bool structure_empty) {
    m_ray = ray;
    m_mode = mode;
    m_hit = Hit{};
    m_work = WorkCounts{};
    m_stack_size = 0;
    if (!ray_is_valid(ray) || structure_empty) {
        finish();
        return false;
    }
    m_box = ray_box_precompute(ray);
    m_tri = ray_triangle_precompute(ray);
    m_hit.t = ray.tmax;  // the current best distance while traversing
    m_cull_t = detail::cull_distance(ray.tmax);
    m_plan.reset(kNoLocality);
    m_plan.add_op(OpKind::box, 1);
    return true;
}

void CellStepper::finish() {
    if (m_hit.prim < 0) m_hit = Hit{};
    m_plan.finish();
}

bool ListCellStepper::list_step(const RefListView& view, StepOutcome& out) {
    if (m_list_arriving) {
        m_list_arriving = false;
        m_list.list_fetched(m_work);
    } else {
        bool done = false;
        out.add_op(OpKind::anyhit,
                   m_mode == TraversalMode::any_hit
                       ? m_list.test_batch<true>(view, m_tri, m_ray.tmin, m_ray.tmax, m_hit, m_cull_t, m_mailbox, m_work, &done)
                       : m_list.test_batch<false>(view, m_tri, m_ray.tmin, m_ray.tmax, m_hit, m_cull_t, m_mailbox, m_work, &done));
        if (done) {
            finish();
            return true;
        }
    }
    return m_list.plan_batch(view, m_mailbox, m_work, m_plan);
}

}  // namespace rtsim
