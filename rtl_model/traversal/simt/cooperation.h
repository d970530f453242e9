#pragma once
// Cooperative lanes (traversal.simt.cooperative; CoopRT, "Accelerating BVH Traversal for Ray
// Tracing via Cooperative Threads", ISCA 2025; simt_unit.h): a ray's walk as a tree of steps that
// idle lanes of its warp may run in parallel, and which ray a lane without one of its own helps.
// The SIMT unit and its functional warp profile (the analytic level's) both use these, so the two
// agree on what cooperation buys.
//
// CooperativeWalk steps the ray's whole walk ahead, functionally, when the ray starts: its hit and
// work counts are then final and are the sequential walk's, so they match the reference exactly.
// Each step depends on the step whose node it visits: the step that descended into it, or the
// one that pushed it onto the stack (a pop takes an entry pushed earlier). CoopRT hands a helper a
// stack entry and the helper walks that subtree with its own traversal state; here every step
// whose parent has run is ready, and the warp's lanes run ready steps in any order the tree
// allows, earliest first. What this leaves out: a helper walks with the best hit the ray had when
// it took the entry, so CoopRT may visit nodes the sequential walk culls by a later hit (our work
// is the sequential walk's, a lower bound on theirs), and the stack spills are the sequential
// walk's. Steps of a reduced-precision extra walk or a restart's re-descent depend on the step
// before them (they are planned in sequence).
#include <algorithm>
#include <cstdint>
#include <vector>

#include "rtl_model/traversal/step_demand.h"

namespace rtsim {

/// The step class of a plan a warp runs one of per warp step: its first operation's kind, or
/// kOpKindCount for a step with none.
inline uint32_t warp_step_class(const StepPlan& plan) { return plan.op_count ? uint32_t(plan.op[0].kind) : kOpKindCount; }

class CooperativeWalk {
public:
    static constexpr uint32_t kNone = 0xFFFFFFFFu;

    /// Runs `stepper` (begun) to its end, recording every step: its reads, its demand under
    /// `costs` (with the ray's `stack` mapped as it goes), its class and the step it depends on;
    /// and, with `prefetch_entries`, the reads of the top entries a popping step leaves on the
    /// stack (stack-driven prefetching, stack_prefetcher.h). Null `costs`: no demand (profiles).
    void record(Stepper& stepper, StackSplit& stack, const StepCosts* costs, uint32_t prefetch_entries = 0) {
        m_steps.clear(), m_fetches.clear(), m_issues.clear(), m_prefetch.clear();
        m_ready.clear(), m_pending.clear(), m_children.clear(), m_child_begin.clear();
        m_taken = 0;
        std::vector<uint32_t> pusher;  // per stack slot: the step that pushed it
        uint32_t parent = kNone;
        while (!stepper.plan().done) {
            const StepPlan& plan = stepper.plan();
            Step s;
            s.parent = parent;
            s.cls = warp_step_class(plan);
            s.locality = plan.locality;
            s.fetch_begin = uint32_t(m_fetches.size());
            const int before = stepper.stack_size();
            if (costs) {
                StepDemand d;
                take_step_reading(stepper, stack, *costs, d, [&](const Fetch& f) { m_fetches.push_back(f); });
                s.issue_begin = uint32_t(m_issues.size());
                m_issues.insert(m_issues.end(), d.issues, d.issues + d.issue_count);
                s.issue_count = d.issue_count;
                s.spill_first = d.spill_first, s.spills = d.spills, s.fill_first = d.fill_first, s.fills = d.fills;
                s.scheduler_slots = d.scheduler_slots;
            } else {
                m_fetches.insert(m_fetches.end(), plan.fetch, plan.fetch + plan.fetch_count);
                stepper.execute();
            }
            s.fetch_count = uint32_t(m_fetches.size()) - s.fetch_begin;
            const uint32_t me = uint32_t(m_steps.size());
            const int after = stepper.stack_size();
            s.prefetch_begin = uint32_t(m_prefetch.size());
            if (after < before) {
                // A pop took the entry at slot `after` (those above it were culled): its pusher.
                parent = size_t(after) < pusher.size() ? pusher[size_t(after)] : me;
                pusher.resize(size_t(std::max(after, 0)));
                if (prefetch_entries && !stepper.done()) {
                    Fetch top[8];
                    const uint32_t n = stepper.stack_reads(top, std::min<uint32_t>(prefetch_entries, 8));
                    m_prefetch.insert(m_prefetch.end(), top, top + n);
                }
            } else {
                pusher.resize(size_t(after), me);  // the entries it pushed; its nearest child is next
                parent = me;
            }
            s.prefetch_count = uint32_t(m_prefetch.size()) - s.prefetch_begin;
            m_steps.push_back(s);
        }
        // Children lists (a step's dependants), parents always before children.
        m_child_begin.assign(m_steps.size() + 1, 0);
        for (const Step& s : m_steps)
            if (s.parent != kNone) ++m_child_begin[s.parent + 1];
        for (size_t i = 1; i < m_child_begin.size(); ++i) m_child_begin[i] += m_child_begin[i - 1];
        m_children.resize(m_child_begin.back());
        std::vector<uint32_t> fill(m_child_begin.begin(), m_child_begin.end() - 1);
        for (uint32_t i = 0; i < m_steps.size(); ++i)
            if (m_steps[i].parent != kNone) m_children[fill[m_steps[i].parent]++] = i;
        if (!m_steps.empty()) m_ready.push_back(0);
    }

    bool done() const { return m_taken == m_steps.size(); }
    size_t steps() const { return m_steps.size(); }

    /// Steps taken in the last warp step have run: their dependants are ready.
    void release() {
        if (m_pending.empty()) return;
        m_ready.insert(m_ready.end(), m_pending.begin(), m_pending.end());
        m_pending.clear();
        std::sort(m_ready.begin(), m_ready.end());
    }
    /// The class of the earliest ready step (the sequential walk's next), or `none` if none is.
    uint32_t next_class(uint32_t none) const { return m_ready.empty() ? none : m_steps[m_ready.front()].cls; }
    /// Ready steps of class `cls`.
    int ready(uint32_t cls) const {
        return int(std::count_if(m_ready.begin(), m_ready.end(), [&](uint32_t i) { return m_steps[i].cls == cls; }));
    }

    /// Takes the earliest ready step of class `cls`: its reads to `read(const Fetch&)`, its demand
    /// into `d` (reads left empty, as take_step_reading leaves them), the reads stack-driven
    /// prefetching requests after it to `prefetch(const Fetch&)`; returns its locality key. Its
    /// dependants are ready after release().
    template <class Read, class Prefetch>
    uint32_t take(uint32_t cls, StepDemand& d, Read&& read, Prefetch&& prefetch) {
        const auto it = std::find_if(m_ready.begin(), m_ready.end(), [&](uint32_t i) { return m_steps[i].cls == cls; });
        const uint32_t i = *it;
        m_ready.erase(it);
        ++m_taken;
        const Step& s = m_steps[i];
        for (uint32_t f = 0; f < s.fetch_count; ++f) read(m_fetches[s.fetch_begin + f]);
        d.read_count = 0;
        d.issue_count = uint8_t(s.issue_count);
        std::copy(m_issues.begin() + s.issue_begin, m_issues.begin() + s.issue_begin + s.issue_count, d.issues);
        d.spill_first = s.spill_first, d.spills = s.spills, d.fill_first = s.fill_first, d.fills = s.fills;
        d.scheduler_slots = s.scheduler_slots;
        for (uint32_t p = 0; p < s.prefetch_count; ++p) prefetch(m_prefetch[s.prefetch_begin + p]);
        m_pending.insert(m_pending.end(), m_children.begin() + m_child_begin[i], m_children.begin() + m_child_begin[i + 1]);
        return s.locality;
    }

private:
    struct Step {
        uint32_t parent = kNone;
        uint32_t cls = 0;
        uint32_t locality = kNoLocality;
        uint32_t fetch_begin = 0, fetch_count = 0;
        uint32_t issue_begin = 0, issue_count = 0;
        uint32_t spill_first = 0, spills = 0, fill_first = 0, fills = 0;
        uint32_t scheduler_slots = kSchedulerSlotsPerStep;
        uint32_t prefetch_begin = 0, prefetch_count = 0;
    };
    std::vector<Step> m_steps;
    std::vector<Fetch> m_fetches, m_prefetch;
    std::vector<OpIssue> m_issues;
    std::vector<uint32_t> m_children, m_child_begin;
    std::vector<uint32_t> m_ready, m_pending;  ///< step indices: ready now, ready after release()
    size_t m_taken = 0;
};

/// The lane in [first, first + lanes) whose ray a helper steps next: among those `eligible(l)`,
/// the one with the most independent work of the warp's kind left (`work(l)`, at least one);
/// `first + lanes` when none.
template <class Work, class Eligible>
uint32_t pick_helped_lane(uint32_t first, uint32_t lanes, Work&& work, Eligible&& eligible) {
    uint32_t best = first + lanes;
    int most = 0;
    for (uint32_t l = first; l < first + lanes; ++l) {
        const int s = work(l);
        if (s > most && eligible(l)) best = l, most = s;
    }
    return best;
}

}  // namespace rtsim
