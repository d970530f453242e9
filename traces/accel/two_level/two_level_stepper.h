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
#include <memory>
#include <vector>

#include "traces/accel/bvh2/bvh2_kernel.h"
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

private:
    void visit_node(const HwNode& node);
    void enter_instance(const InstanceRecord& record);
    StepOutcome blas_step();
    void leave_instance();
    void pop_next();
    void plan_tlas();
    void plan_blas();
    void finish();

    const TwoLevelAccel& m_accel;
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
};

}  // namespace rtsim
