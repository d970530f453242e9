// The step-demand function: what a step costs (reads, issues per operation kind at the pipelines'
// widths, stack spills and fills, scheduler slots), the one rule every consumer of plans uses.
#include <gtest/gtest.h>

#include <vector>

#include "rtl_model/traversal/step_demand.h"
#include "tests/cpp/error_of.h"

namespace rtsim {
namespace {

StepCosts costs(uint32_t stack_entries) {
    StepCosts c;
    c.stack_entries = stack_entries;
    c.stack_entry_bytes = 8;
    c.width[size_t(OpKind::box)] = 4;
    c.width[size_t(OpKind::triangle)] = 1;
    c.width[size_t(OpKind::anyhit)] = 2;
    return c;
}

/// A stepper that plays a script: each step fetches one node, tests `boxes` boxes, reports
/// `alpha` alpha tests and leaves the stack at `depth`.
struct Scripted {
    uint32_t boxes, alpha;
    int depth;
};
class ScriptStepper : public Stepper {
public:
    explicit ScriptStepper(std::vector<Scripted> script) : m_script(std::move(script)) {}
    void begin(const Ray& ray, TraversalMode mode) override {
        m_ray = ray;
        m_mode = mode;
        m_next = 0;
        m_stack_size = 0;
        plan_next();
    }
    StepOutcome execute() override {
        StepOutcome out;
        out.add_op(OpKind::anyhit, m_script[m_next].alpha);
        m_stack_size = m_script[m_next].depth;
        ++m_work.steps;
        ++m_next;
        plan_next();
        return out;
    }

private:
    void plan_next() {
        if (m_next == m_script.size()) return m_plan.finish();
        m_plan.reset(uint32_t(m_next));
        m_plan.add_fetch(64 * m_next, 64, DataKind::node);
        m_plan.add_op(OpKind::box, m_script[m_next].boxes);
    }
    std::vector<Scripted> m_script;
    size_t m_next = 0;
};

TEST(StepDemand, IssuesPerKindAtThePipelineWidthInOrder) {
    StepPlan plan;
    plan.reset(0);
    plan.add_fetch(128, 64, DataKind::node);
    plan.add_fetch(4096, 96, DataKind::triangle);
    plan.add_op(OpKind::box, 6);
    plan.add_op(OpKind::triangle, 2);
    StepOutcome outcome;
    outcome.add_op(OpKind::anyhit, 3);
    StackSplit stack;
    const StepDemand d = step_demand(plan, outcome, 0, 0, stack, costs(8));
    ASSERT_EQ(d.read_count, 2);
    EXPECT_EQ(d.reads[1].addr, 4096u);
    EXPECT_EQ(d.reads[1].kind, DataKind::triangle);
    ASSERT_EQ(d.issue_count, 3);
    EXPECT_EQ(d.issues[0].kind, OpKind::box);
    EXPECT_EQ(d.issues[0].tests, 6u);
    EXPECT_EQ(d.issues[0].issues, 2u);  // 6 boxes at width 4
    EXPECT_EQ(d.issues[1].issues, 2u);  // 2 triangles at width 1
    EXPECT_EQ(d.issues[2].kind, OpKind::anyhit);  // what the results called for, last
    EXPECT_EQ(d.issues[2].issues, 2u);
    EXPECT_EQ(d.scheduler_slots, kSchedulerSlotsPerStep);
    EXPECT_EQ(issues_for(0, 4), 0u);
    EXPECT_EQ(issues_for(4, 4), 1u);
    EXPECT_EQ(issues_for(5, 4), 2u);
}

TEST(StepDemand, StackSpillsOldestAndFillsNewestSlots) {
    StackSplit stack;
    StepPlan plan;
    plan.reset(0);
    // Push 5 onto 2 on-chip entries: 3 spill, to slots 0, 1, 2.
    StepDemand d = step_demand(plan, StepOutcome{}, 0, 5, stack, costs(2));
    std::vector<uint32_t> spilled, filled;
    d.for_each_spill([&](uint32_t s) { spilled.push_back(s); });
    EXPECT_EQ(spilled, (std::vector<uint32_t>{0, 1, 2}));
    EXPECT_EQ(d.fills, 0u);
    EXPECT_EQ(stack.local, 2u);
    EXPECT_EQ(stack.spilled, 3u);
    // Pop 4: the 2 on chip first, then 2 read back, newest first (slots 2, 1).
    d = step_demand(plan, StepOutcome{}, 5, 1, stack, costs(2));
    d.for_each_fill([&](uint32_t s) { filled.push_back(s); });
    EXPECT_EQ(filled, (std::vector<uint32_t>{2, 1}));
    EXPECT_EQ(d.spills, 0u);
    EXPECT_EQ(stack.local, 0u);
    EXPECT_EQ(stack.spilled, 1u);
}

TEST(StepDemand, AKindWithNoPipelineIsAnErrorNamingIt) {
    StepPlan plan;
    plan.reset(0);
    plan.add_op(OpKind::plane, 2);
    StackSplit stack;
    const std::string e = test::error_of([&] { step_demand(plan, StepOutcome{}, 0, 0, stack, costs(8)); });
    EXPECT_NE(e.find("'plane'"), std::string::npos) << e;
    EXPECT_NE(e.find("no pipeline"), std::string::npos) << e;
}

TEST(StepDemand, TakeStepCostsThePlanThatRanNotTheNextOne) {
    ScriptStepper stepper({{3, 0, 4}, {8, 1, 12}, {1, 0, 0}});
    stepper.begin(Ray{}, TraversalMode::closest_hit);
    StackSplit stack;
    StepDemand d;
    std::vector<uint32_t> box_issues, spills, fills;
    while (!stepper.done()) {
        take_step(stepper, stack, costs(8), d);
        box_issues.push_back(d.issues[0].issues);
        spills.push_back(d.spills);
        fills.push_back(d.fills);
    }
    EXPECT_EQ(box_issues, (std::vector<uint32_t>{1, 2, 1}));  // 3, 8, 1 boxes at width 4
    EXPECT_EQ(spills, (std::vector<uint32_t>{0, 4, 0}));      // depth 4, then 12 on 8 entries
    EXPECT_EQ(fills, (std::vector<uint32_t>{0, 0, 4}));
    EXPECT_EQ(stack.local + stack.spilled, 0u);
}

}  // namespace
}  // namespace rtsim
