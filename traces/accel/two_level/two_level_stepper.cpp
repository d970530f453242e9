// The two-level stepper (two_level_stepper.h): the TLAS walk is the binary BVH's (bvh2_kernel.h),
// the BLAS walks are their kinds' own steppers on the object-space ray.
#include "traces/accel/two_level/two_level_stepper.h"

#include "traces/accel/two_level/two_level.h"

namespace rtsim {

using detail::cull_distance;

TwoLevelStepper::TwoLevelStepper(const TwoLevelAccel& accel, const StepOptions& options)
    : m_accel(accel), m_anyhit_order(options.anyhit_order) {
    for (const auto& blas : accel.blases()) m_blas_steppers.push_back(blas->make_stepper(options));
    m_short.configure(options.short_stack_entries);
}

void TwoLevelStepper::begin(const Ray& ray, TraversalMode mode) {
    m_ray = ray;
    m_mode = mode;
    m_hit = Hit{};
    m_work = WorkCounts{};
    m_stack_size = m_tlas_size = 0;
    m_inner = nullptr;
    m_depth = 0;
    m_short.begin();
    if (!ray_is_valid(ray) || m_accel.tlas().node_count == 0) {
        finish();
        return;
    }
    m_box = ray_box_precompute(ray);
    m_hit.t = ray.tmax;  // the current best distance while traversing
    m_cull_t = cull_distance(ray.tmax);
    m_ref = 0;
    m_count = 0;
    plan_tlas();
}

uint32_t TwoLevelStepper::stack_reads(Fetch* out, uint32_t max) const {
    uint32_t n = m_inner ? m_inner->stack_reads(out, max) : 0;
    for (int i = m_tlas_size - 1; i >= 0 && n < max; --i, ++n) {
        const detail::Bvh2StackEntry& e = m_stack[i];
        out[n] = e.count == 0 ? Fetch{m_accel.tlas().node_base + uint64_t(e.ref) * sizeof(HwNode), uint32_t(sizeof(HwNode)),
                                      DataKind::node}
                              : Fetch{m_accel.instances().base + uint64_t(e.ref) * sizeof(InstanceRecord),
                                      kInstanceFetchBytes, DataKind::instance};
    }
    return n;
}

void TwoLevelStepper::plan_tlas() {
    const Bvh2View& tlas = m_accel.tlas();
    if (m_count == 0) {
        m_plan.reset(m_accel.tlas_key_base() + m_ref);
        m_plan.add_fetch(tlas.node_base + uint64_t(m_ref) * sizeof(HwNode), sizeof(HwNode), DataKind::node);
        m_plan.add_op(OpKind::box, 2);
    } else {
        m_plan.reset(kNoLocality);  // an instance record belongs to its TLAS node's treelet
        m_plan.add_fetch(m_accel.instances().base + uint64_t(m_ref) * sizeof(InstanceRecord), kInstanceFetchBytes,
                         DataKind::instance);
        m_plan.add_op(OpKind::transform, 1);
    }
    m_stack_size = m_tlas_size;
}

void TwoLevelStepper::plan_blas() {
    m_plan = m_inner->plan();
    if (m_plan.locality != kNoLocality) m_plan.locality += m_inner_offset;
    m_stack_size = m_tlas_size + m_inner->stack_size();
}

StepOutcome TwoLevelStepper::execute() {
    if (m_plan.done) return StepOutcome{};
    if (m_inner) return blas_step();
    if (m_short.replaying()) replay_step();
    else if (m_count == 0) visit_node(m_accel.tlas().nodes[m_ref]);
    else enter_instance(m_accel.instances().records[m_ref]);
    return StepOutcome{};
}

void TwoLevelStepper::visit_node(const HwNode& node) {
    // The binary BVH's node step (bvh2_kernel.h): nearer child next (any-hit rays by their
    // order), the other pushed.
    m_work.tlas_steps += 1;  // the TLAS's share of steps and box tests (descend counts both)
    m_work.tlas_box_tests += 2;
    const int before = m_tlas_size;
    if (m_short.enabled()) m_short.visit(m_ref, m_depth);
    const AnyHitOrder order = m_mode == TraversalMode::any_hit ? m_anyhit_order : AnyHitOrder::nearest;
    if (!detail::descend(m_box, node, m_ray.tmin, m_cull_t, m_work, m_stack, m_tlas_size, &m_ref, &m_count, order))
        return pop_next();
    if (m_short.enabled()) {
        if (m_tlas_size > before) {
            m_entry_depth[m_tlas_size - 1] = m_depth + 1;
            if (m_short.push()) m_work.stack_drops += 1;
        }
        m_depth += 1;
    }
    plan_tlas();
}

void TwoLevelStepper::enter_instance(const InstanceRecord& record) {
    m_work.transforms += 1;
    Ray object_ray = transform_ray(record.world_to_object, m_ray);
    object_ray.tmax = m_hit.t;  // t is the same in both spaces: nothing beyond the best hit
    m_instance = &record;
    m_inner_offset = m_accel.locality_offset(record.blas);
    m_inner = m_blas_steppers[record.blas].get();
    m_inner->begin(object_ray, m_mode);
    if (m_inner->done()) leave_instance();
    else plan_blas();
}

StepOutcome TwoLevelStepper::blas_step() {
    const StepOutcome out = m_inner->execute();
    if (m_inner->done()) leave_instance();
    else plan_blas();
    return out;
}

void TwoLevelStepper::leave_instance() {
    m_work += m_inner->work();
    const Hit& h = m_inner->hit();
    m_inner = nullptr;
    if (h.valid()) {
        // Merge with global primitive ids, so ties between instances break as in a flat scene.
        const uint32_t prim = m_instance->prim_base + uint32_t(h.prim);
        if (m_mode == TraversalMode::any_hit || detail::closer(h.t, prim, m_hit.t, m_hit.prim)) {
            m_hit = Hit{int32_t(prim), int32_t(m_instance->instance), h.t, h.u, h.v};
            m_cull_t = cull_distance(h.t);
            if (m_mode == TraversalMode::any_hit) {
                finish();
                return;
            }
        }
    }
    pop_next();
}

void TwoLevelStepper::pop_next() {
    // With the TLAS's short stack, reaching an entry it dropped means a restart (short_stack.h).
    bool restart = false;
    while (m_tlas_size > 0) {
        const detail::Bvh2StackEntry& e = m_stack[--m_tlas_size];
        if (m_short.enabled()) restart |= m_short.pop();
        if (e.tnear > m_cull_t) continue;  // entered beyond the (widened) best hit
        m_ref = e.ref;
        m_count = e.count;
        if (m_short.enabled()) m_depth = m_entry_depth[m_tlas_size];
        if (restart) return begin_restart(m_depth, true);
        plan_tlas();
        return;
    }
    if (restart) return begin_restart(0, false);
    finish();
}

void TwoLevelStepper::begin_restart(uint32_t depth, bool resume) {
    m_work.restarts += 1;
    m_short.restart(depth, uint32_t(m_tlas_size));
    m_resume = resume;
    plan_replay();
}

void TwoLevelStepper::plan_replay() {
    const uint32_t node = m_short.replay_node();
    m_plan.reset(m_accel.tlas_key_base() + node);
    m_plan.add_fetch(m_accel.tlas().node_base + uint64_t(node) * sizeof(HwNode), sizeof(HwNode), DataKind::node);
    m_plan.add_op(OpKind::box, 2);
    m_stack_size = m_tlas_size;
}

void TwoLevelStepper::replay_step() {
    // A revisit re-tests the TLAS node's child boxes to follow the trail; the walk is unchanged.
    m_work.restart_steps += 1;
    m_work.restart_box_tests += 2;
    m_short.replay_advance();
    if (m_short.replaying()) plan_replay();
    else if (m_resume) plan_tlas();
    else finish();
}

void TwoLevelStepper::finish() {
    if (m_hit.prim < 0) m_hit = Hit{};
    m_plan.finish();
    m_stack_size = 0;
}

}  // namespace rtsim
