#pragma once
// The two-level stepper (docs/accel.md, "Two-level structures"): walks the TLAS like the binary
// BVH (both child boxes per node step, nearer child first, the farther pushed); at a leaf a
// transform step fetches the instance record's first line and runs one transform operation,
// which puts the ray into the instance's object space and starts the BLAS's own stepper on it;
// the BLAS's steps are this stepper's steps until it finishes, when its hit is merged (closest
// by (t, primitive id) with global ids) and the TLAS walk resumes.
//
// Stack: a TLAS entry carries the node (or leaf instance) it resumes at; while a BLAS is walked
// its entries sit above the TLAS entries and belong to the current instance (stack_size() is the
// sum). Locality keys: TLAS nodes keep their index, BLAS b's keys are offset by
// TwoLevelAccel::locality_offset(b). Work counts: TLAS node steps and box tests, one transform
// per instance entered, plus every BLAS walk's own counts.
//
// Restart trails are per level (Laine 2010 on each tree): with a short stack each level keeps
// traversal.stack_entries entries of its own and its own trail. The TLAS walk's shadow
// (short_stack.h) restarts at the TLAS root and re-descends the TLAS; a BLAS walk's restarts
// re-descend that BLAS from its root in the instance's object space (its kind's stepper), so a
// restart never re-enters an instance it is walking. Reduced-precision boxes are the BLASes'
// (their kinds' walks); the TLAS's boxes stay fp32, as instance boxes are few and refit per frame.
#include <memory>
#include <vector>

#include "traces/accel/bvh2/bvh2_kernel.h"
#include "traces/accel/short_stack.h"
#include "traces/accel/step_options.h"
#include "traces/accel/stepper.h"
#include "traces/accel/two_level/instance_record.h"

namespace rtsim {

class TwoLevelAccel;

class TwoLevelStepper final : public Stepper {
public:
    /// The BLASes' steppers walk with `options` (a mailbox, where their kind has one).
    TwoLevelStepper(const TwoLevelAccel& accel, const StepOptions& options);

    void begin(const Ray& ray, TraversalMode mode) override;
    StepOutcome execute() override;
    /// The BLAS's top entries first (while one is walked), then the TLAS's: nodes and instance
    /// records (their first line, as the transform step fetches it).
    uint32_t stack_reads(Fetch* out, uint32_t max) const override;

private:
    void visit_node(const HwNode& node);
    void enter_instance(const InstanceRecord& record);
    StepOutcome blas_step();
    void leave_instance();
    void pop_next();
    void plan_tlas();
    void plan_blas();
    void begin_restart(uint32_t depth, bool resume);
    void plan_replay();
    void replay_step();
    void finish();

    const TwoLevelAccel& m_accel;
    AnyHitOrder m_anyhit_order = AnyHitOrder::nearest;  ///< any-hit rays' TLAS child order (the BLASes' their own)
    std::vector<std::unique_ptr<Stepper>> m_blas_steppers;  ///< one per BLAS, reused
    RayBoxPre m_box;
    float m_cull_t = 0.0f;
    uint32_t m_ref = 0;
    uint32_t m_count = 0;
    int m_tlas_size = 0;
    Stepper* m_inner = nullptr;          ///< the BLAS being walked, or null in the TLAS
    const InstanceRecord* m_instance = nullptr;
    uint32_t m_inner_offset = 0;         ///< locality offset of the BLAS being walked
    detail::Bvh2StackEntry m_stack[kTraversalStackSize];  ///< TLAS entries (ref: node or instance record)
    // The TLAS's short stack only: the current node's depth, each entry's, and the shadow.
    uint32_t m_depth = 0;
    bool m_resume = false;  ///< after the re-descent: m_ref/m_count (true) or the end (false)
    uint32_t m_entry_depth[kTraversalStackSize];
    ShortStack m_short;
};

}  // namespace rtsim
