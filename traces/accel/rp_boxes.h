#pragma once
// The extra walk of a reduced-precision box pipeline (docs/accel.md, "Reduced-precision box
// tests"), kept beside a stepper's fp32 walk so hits and the reference work never change.
//
// A narrower box pipeline (Keely 2014; Vaidyanathan et al. 2016; traces/isect/ray_box_rp.h) is
// conservative: it accepts every box the fp32 test accepts, and some more. The hardware therefore
// visits every node the fp32 walk visits, plus the subtrees below boxes only the reduced test
// accepts, and pops stack entries the fp32 entry distance would have culled. Triangles stay fp32
// watertight; a triangle inside a box the fp32 test rejects for [tmin, cull] cannot be hit there,
// so those subtrees add work and never a hit. The stepper keeps walking with fp32 (the definition
// of hits and reference work) and hands this shadow each such box; the shadow walks its subtree
// right away with the reduced test alone, each node and leaf a planned step of its own (fetch,
// then box or triangle tests), counted in the model-only work fields rp_box_hits, rp_steps,
// rp_box_tests and rp_tri_tests, and then resumes the step the fp32 walk had planned.
//
// Two approximations, said in docs/accel.md: the extra subtree is walked when its box is met,
// with the cull distance of that moment (a hardware walk would order it by entry distance and may
// cull some of it by a later, closer hit: this is an upper bound); the fp32 walk's child order is
// kept (a reduced test's entry distances can order two close children the other way). Its entries
// are not charged to the traversal stack (nor a short stack's shadow).
#include <cstdint>
#include <vector>

#include "traces/accel/step_plan.h"

namespace rtsim {

class ReducedPrecisionBoxes {
public:
    struct Entry {
        uint32_t ref;    ///< node index, or first triangle of a leaf
        uint32_t count;  ///< 0: node; else the leaf's triangle count
    };
    /// bits: the reduced test's mantissa bits; 0 turns the shadow off (the fp32 test alone).
    void configure(uint32_t bits) { m_bits = bits; }
    bool enabled() const { return m_bits != 0; }
    uint32_t bits() const { return m_bits; }

    void begin() { m_stack.clear(), m_walking = false; }
    /// A box the reduced test enters and the fp32 walk does not: its subtree is walked.
    void enter(uint32_t ref, uint32_t count) { m_stack.push_back({ref, count}); }
    /// True when boxes were entered and their walk has not started.
    bool pending() const { return !m_walking && !m_stack.empty(); }
    /// Starts the extra walk; `resume` is the step the fp32 walk planned (or its finish).
    void start(const StepPlan& resume) { m_resume = resume, m_walking = true; }
    bool walking() const { return m_walking; }
    const Entry& next() const { return m_stack.back(); }
    Entry pop() {
        const Entry e = m_stack.back();
        m_stack.pop_back();
        return e;
    }
    bool empty() const { return m_stack.empty(); }
    /// Ends the extra walk: the fp32 walk's planned step.
    const StepPlan& resume() { return m_walking = false, m_resume; }

private:
    uint32_t m_bits = 0;
    bool m_walking = false;
    std::vector<Entry> m_stack;
    StepPlan m_resume;
};

}  // namespace rtsim
