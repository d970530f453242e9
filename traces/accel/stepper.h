#pragma once
// A Stepper walks one ray through one acceleration structure, one step at a time (docs/accel.md):
//
//   begin(ray, mode);
//   while (!plan().done) { ...fetch plan().fetch[], then... execute(); }
//   hit(), work()
//
// The reference tracer's loops, the model's traversal units and the analytic level all drive
// steppers, so they visit the same nodes in the same order and get bit-identical hits with the
// one arithmetic of traces/isect (docs/architecture.md, rules 1 and 3). A stepper reads the
// structure's data from its image in execute(); whoever drives it only times the plan.
#include <cstdint>

#include "traces/accel/step_plan.h"
#include "traces/common/ray.h"

namespace rtsim {

class Stepper {
public:
    virtual ~Stepper() = default;

    /// Starts a ray. Invalid rays (ray_is_valid() false) finish at once with a miss and no work.
    virtual void begin(const Ray& ray, TraversalMode mode) = 0;
    /// Runs the planned step with the one arithmetic on the image's data, then plans the next.
    /// Returns the operations the step's results called for beyond plan().op (alpha tests).
    virtual StepOutcome execute() = 0;

    const StepPlan& plan() const { return m_plan; }
    bool done() const { return m_plan.done; }
    const Hit& hit() const { return m_hit; }
    const WorkCounts& work() const { return m_work; }
    const Ray& ray() const { return m_ray; }
    TraversalMode mode() const { return m_mode; }
    /// Entries on the traversal stack now (the model maps them onto its on-chip stack).
    int stack_size() const { return m_stack_size; }
    /// The reads that visiting the top `max` stack entries would issue, top (next popped) first,
    /// from the addresses a hardware stack holds: what stack-driven prefetching (TTP, Tozlu,
    /// Naithani & Zhou 2026) requests. Entries a pop would skip are included (the stack holds
    /// their addresses either way). Returns how many it wrote; 0 from a structure whose stack
    /// holds no addresses (capabilities.h: stack_addresses).
    virtual uint32_t stack_reads(Fetch* out, uint32_t max) const {
        (void)out;
        (void)max;
        return 0;
    }

protected:
    StepPlan m_plan;
    Hit m_hit;
    WorkCounts m_work;
    Ray m_ray;
    TraversalMode m_mode = TraversalMode::closest_hit;
    int m_stack_size = 0;
};

}  // namespace rtsim
