#include "rtl_model/traversal/step_demand.h"

#include <algorithm>
#include <string>

#include "traces/common/error.h"

namespace rtsim {

namespace {

void plan_demand(const StepPlan& plan, const StepCosts& costs, StepDemand& d) {
    d.read_count = plan.fetch_count;
    std::copy(plan.fetch, plan.fetch + plan.fetch_count, d.reads);
    step_parts::plan_issues(plan, costs, d);
}

void outcome_demand(const StepOutcome& outcome, const StepCosts& costs, StepDemand& d) {
    for (int i = 0; i < outcome.op_count; ++i) step_parts::add_issue(outcome.op[i], costs, d);
}

/// Pushes beyond the on-chip entries spill the oldest entry to the next spill slot; pops with
/// no entry on chip read the newest spilled one back (docs/model.md, "Traversal stack").
void stack_demand(int before, int after, StackSplit& stack, const StepCosts& costs, StepDemand& d) {
    d.spill_first = stack.spilled;
    d.spills = d.fills = 0;
    for (int i = before; i < after; ++i) {
        if (stack.local < costs.stack_entries) ++stack.local;
        else ++stack.spilled, ++d.spills;
    }
    d.fill_first = stack.spilled - 1;
    for (int i = after; i < before; ++i) {
        if (stack.local > 0) --stack.local;
        else --stack.spilled, ++d.fills;
    }
}

}  // namespace

StepDemand step_demand(const StepPlan& plan, const StepOutcome& outcome, int stack_before, int stack_after,
                       StackSplit& stack, const StepCosts& costs) {
    StepDemand d;
    plan_demand(plan, costs, d);
    outcome_demand(outcome, costs, d);
    stack_demand(stack_before, stack_after, stack, costs, d);
    return d;
}

void take_step(Stepper& stepper, StackSplit& stack, const StepCosts& costs, StepDemand& d) {
    plan_demand(stepper.plan(), costs, d);  // execute() plans the next step over this one
    step_parts::run_and_cost(stepper, stack, costs, d);
}

namespace step_parts {

void no_pipeline(OpKind kind) {
    throw Error(std::string("model: a step issued '") + op_kind_name(kind) +
                "' operations but the machine has no pipeline for them");
}

void run_and_cost(Stepper& stepper, StackSplit& stack, const StepCosts& costs, StepDemand& d) {
    const int before = stepper.stack_size();
    outcome_demand(stepper.execute(), costs, d);
    stack_demand(before, stepper.stack_size(), stack, costs, d);
}

}  // namespace step_parts

}  // namespace rtsim
