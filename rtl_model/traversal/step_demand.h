#pragma once
// The one way to cost a traversal step (docs/model.md, "Costing a step"). From a step's plan,
// the operations its results called for and the ray's stack before and after, under the
// machine's traversal and pipeline configs, the step-demand function says what the step asks of
// the machine:
//
//   reads     the plan's fetches, issued together; the step's operations wait for all of them
//   issues    per operation, in order (the plan's, then the ones its results called for): its
//             tests and the pipeline issues they take at the pipeline's width
//   stack     entries spilled to memory (posted writes) and filled back (reads the ray waits
//             for) as the ray's stack is mapped onto `stack_entries` on-chip entries
//   slots     scheduler slots: a step is two phases (fetch, then operations), a ray one more
//             (its ray-record fetch and its end)
//
// Plain C++, no SystemC. The traversal units, both paths of the analytic level and sampling's
// functional warming cost steps only through it, so a timing rule is written once and an
// operation kind with no pipeline is an error, never a default.
#include <algorithm>
#include <array>
#include <cstdint>

#include "rtl_model/common/stack_split.h"
#include "rtl_model/isect/pipeline_config.h"
#include "rtl_model/traversal/traversal_config.h"
#include "traces/accel/stepper.h"

namespace rtsim {

/// Scheduler slots of one ray besides its steps: the ray-record fetch (with its first step's
/// fetches) and the step that finds the ray done and writes its hit.
constexpr uint32_t kSchedulerSlotsPerRay = 1;
/// Scheduler slots of one step: its fetch phase and its operations phase.
constexpr uint32_t kSchedulerSlotsPerStep = 2;

/// Pipeline issues `tests` tests take at `width` tests per issue.
inline uint32_t issues_for(uint32_t tests, uint32_t width) {
    if (tests <= width) return tests ? 1 : 0;
    return width == 1 ? tests : (tests + width - 1) / width;  // width 1 (the default) needs no division
}

/// What costing depends on, resolved once per run: the stack's size and each operation kind's
/// pipeline width (0: the machine has no pipeline for the kind).
struct StepCosts {
    uint32_t stack_entries = 8;
    uint32_t stack_entry_bytes = 8;
    std::array<uint32_t, kOpKindCount> width{};

    /// `pipeline(kind)` gives the config of each kind in `kinds` (the kinds the structure issues).
    template <class PipelineOf, class Kinds>
    static StepCosts of(const TraversalConfig& traversal, const Kinds& kinds, PipelineOf&& pipeline) {
        StepCosts c;
        // A short stack drops entries instead of spilling them: no stack traffic, restart steps instead.
        c.stack_entries = traversal.stack_overflow == StackOverflow::spill ? traversal.stack_entries : UINT32_MAX;
        c.stack_entry_bytes = traversal.stack_entry_bytes;
        for (OpKind k : kinds) c.width[size_t(k)] = pipeline(k).width;
        return c;
    }
};

/// One operation as the pipelines take it.
struct OpIssue {
    OpKind kind = OpKind::box;
    uint32_t tests = 0;
    uint32_t issues = 0;
};

struct StepDemand {
    static constexpr int kMaxIssues = StepPlan::kMaxOps + StepOutcome::kMaxOps;

    uint8_t read_count = 0;
    uint8_t issue_count = 0;
    Fetch reads[StepPlan::kMaxFetches];
    OpIssue issues[kMaxIssues];
    /// Stack entries written to spill slots spill_first, spill_first + 1, ... (posted writes).
    uint32_t spill_first = 0, spills = 0;
    /// Stack entries read back from slots fill_first, fill_first - 1, ... (the ray waits).
    uint32_t fill_first = 0, fills = 0;
    uint32_t scheduler_slots = kSchedulerSlotsPerStep;

    template <class F>
    void for_each_spill(F&& f) const {
        for (uint32_t i = 0; i < spills; ++i) f(spill_first + i);
    }
    template <class F>
    void for_each_fill(F&& f) const {
        for (uint32_t i = 0; i < fills; ++i) f(fill_first - i);
    }
};

/// The step-demand function: what the step of `plan` (as planned, before it ran) costs, given
/// the operations its results called for and its stack depth before and after; updates `stack`.
/// Throws rtsim::Error naming an operation kind the machine has no pipeline for.
StepDemand step_demand(const StepPlan& plan, const StepOutcome& outcome, int stack_before, int stack_after,
                       StackSplit& stack, const StepCosts& costs);

/// Runs the stepper's planned step (its plan must not be done) and costs it into `demand` (the
/// step-demand function, without copying the plan): what every consumer of plans calls.
void take_step(Stepper& stepper, StackSplit& stack, const StepCosts& costs, StepDemand& demand);

namespace step_parts {
/// Throws rtsim::Error: a step issued operations of `kind` and the machine has no pipeline for them.
[[noreturn]] void no_pipeline(OpKind kind);
/// Appends the issues of `op` at its pipeline's width (inline: every step of every unit calls it).
inline void add_issue(const Op& op, const StepCosts& costs, StepDemand& d) {
    const uint32_t width = costs.width[size_t(op.kind)];
    if (width == 0) no_pipeline(op.kind);
    d.issues[d.issue_count++] = OpIssue{op.kind, op.count, issues_for(op.count, width)};
}
/// The issues of the plan's operations (take_step's first part, after the reads).
inline void plan_issues(const StepPlan& plan, const StepCosts& costs, StepDemand& d) {
    d.issue_count = 0;
    for (int i = 0; i < plan.op_count; ++i) add_issue(plan.op[i], costs, d);
    d.scheduler_slots = kSchedulerSlotsPerStep;
}
/// Runs the planned step, then costs the operations its results called for and its stack.
void run_and_cost(Stepper& stepper, StackSplit& stack, const StepCosts& costs, StepDemand& demand);
}  // namespace step_parts

/// take_step with the plan's fetches handed to `read(const Fetch&)` in order, in place, before
/// the step runs (demand.reads is left empty, read_count 0): a traversal unit issues them to
/// its memory as they are, instead of copying them first. The demand is otherwise take_step's.
template <class Read>
void take_step_reading(Stepper& stepper, StackSplit& stack, const StepCosts& costs, StepDemand& demand, Read&& read) {
    const StepPlan& plan = stepper.plan();
    for (int i = 0; i < plan.fetch_count; ++i) read(plan.fetch[i]);
    demand.read_count = 0;
    step_parts::plan_issues(plan, costs, demand);
    step_parts::run_and_cost(stepper, stack, costs, demand);
}

/// Calls f(line, bytes in it) for each line (of 1 << line_shift bytes) that [addr, addr + bytes)
/// touches (a zero-byte access touches the line of addr), as the caches split a request.
template <class F>
void for_each_line(uint64_t addr, uint32_t bytes, uint32_t line_shift, F&& f) {
    const uint64_t end = addr + (bytes ? bytes : 1);
    for (uint64_t line = addr >> line_shift; line <= (end - 1) >> line_shift; ++line) {
        const uint64_t lo = std::max(addr, line << line_shift), hi = std::min<uint64_t>(addr + bytes, (line + 1) << line_shift);
        f(line, uint32_t(hi > lo ? hi - lo : 0));
    }
}

}  // namespace rtsim
