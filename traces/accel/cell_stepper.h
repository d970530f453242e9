#pragma once
// What the space-partitioning steppers (grid, kd-tree, BIH, octree; docs/accel.md) share: a ray
// starts with one clip step against the root cell (no fetch, one box test), walks cells front to
// back while its cull distance shrinks, and ends with the empty hit when it found nothing.
// Cells that hold reference lists test them in batches (ref_list.h). The kd-tree and the BIH
// also share their descent: the near child next, the far one pushed with its interval.
#include <algorithm>
#include <cstdint>
#include <string>

#include "traces/accel/mailbox.h"
#include "traces/accel/ref_list.h"
#include "traces/accel/short_stack.h"
#include "traces/accel/stepper.h"
#include "traces/common/aabb.h"
#include "traces/common/error.h"
#include "traces/isect/ray_box.h"
#include "traces/isect/ray_triangle.h"
#include "traces/isect/slab_interval.h"

namespace rtsim {

class CellStepper : public Stepper {
protected:
    /// Resets the ray's state and plans the clip step. False when the ray is invalid or the
    /// structure empty: the ray is then finished, a miss with no work.
    bool start(const Ray& ray, TraversalMode mode, bool structure_empty);
    /// Ends the ray: a miss reports the empty hit, not its shrunken search distance.
    void finish();

    RayBoxPre m_box;
    RayTrianglePre m_tri;
    float m_cull_t = 0.0f;  ///< cells entered beyond this are not visited: the best t, widened
};

/// The cells or leaves that list their triangles by reference (grid, kd-tree, octree): a list's
/// fetch is one step, then each step tests one batch (ref_list.h), with the ray's mailbox.
class ListCellStepper : public CellStepper {
protected:
    explicit ListCellStepper(uint32_t mailbox_entries) { m_mailbox.set_entries(mailbox_entries); }

    /// CellStepper::start with an empty mailbox: a ray skips only what it tested itself.
    bool start(const Ray& ray, TraversalMode mode, bool structure_empty) {
        m_mailbox.clear();
        return CellStepper::start(ray, mode, structure_empty);
    }
    /// Plans the fetch of list [first, first + count) (count > 0); list_step takes it from there.
    void open_list(const RefListView& view, uint32_t first, uint32_t count) {
        m_list_arriving = true;
        m_list.plan_list(view, first, count, m_plan);
    }
    /// One step of the open list: its arrival (counted, the first batch planned) or the planned
    /// batch's tests (the ray's mode picks the hit rule; alpha tests into `out`). False when the
    /// list is used up and nothing is planned: the caller goes on to its next cell. An any-hit
    /// ray that has its hit is finished here.
    bool list_step(const RefListView& view, StepOutcome& out);

private:
    Mailbox m_mailbox;
    RefListWalk m_list;
    bool m_list_arriving = false;
};

/// The binary partitions' clip step and descent (kd-tree, BIH): Derived has visit(node, interval)
/// and plan_node(node) (the fetch and operations of an interior node's step; friends of this
/// base), kName for the stack-overflow error, kNodeTests (the tests an interior node runs) and
/// kPushDown; Base is CellStepper or, for leaves with reference lists, ListCellStepper.
///
/// With a short stack (StepOptions::short_stack_entries, short_stack.h) the walk keeps its full
/// stack, so hits and the reference work never change, and the shadow says when the hardware's
/// short stack runs empty with entries dropped and which nodes its re-descent revisits, counted
/// in the model-only restart fields. With kPushDown (the kd-tree: kd-restart with push-down,
/// Foley & Sugerman 2005, behind a short stack as Horn et al. 2007 do) the re-descent starts at
/// the deepest node whose cell holds all the ray still has to visit: the parent of the shallowest
/// entry still pending (those a closer hit culls later are counted as pending, so it may start
/// higher than the hardware would). Without it (the BIH, whose children overlap) it starts at the
/// root and follows a restart trail (Laine 2010), as the BVHs' do.
template <class Derived, uint32_t kMaxDepth, class Base = CellStepper>
class BinaryCellStepper : public Base {
protected:
    struct Entry {
        uint32_t node;
        detail::SlabInterval cell;
    };

    using Base::Base;

    /// On-chip entries of the short stack (0: a full stack).
    void configure_short_stack(uint32_t entries) { m_short.configure(entries); }
    /// Resets the shadow: call from begin().
    void begin_walk() {
        m_depth = 0;
        m_short.begin();
    }

    /// The clip step: the ray against the root cell (one box test), then the root node.
    void clip(const Aabb& root) {
        this->m_work.box_tests += 1;
        const float lo[3] = {root.lo.x, root.lo.y, root.lo.z}, hi[3] = {root.hi.x, root.hi.y, root.hi.z};
        const detail::SlabInterval cell = detail::slab_box(this->m_box, lo, hi, this->m_ray.tmin);
        if (!detail::slab_hit(cell, this->m_cull_t)) return this->finish();
        go(0, cell, 0);
    }

    /// Goes on to the child the ray enters first (`low` when it runs up the split axis), pushing
    /// the other when the ray enters both; pops the next pending cell when it enters neither.
    void descend(uint32_t low_node, const detail::SlabInterval& low, uint32_t high_node,
                 const detail::SlabInterval& high, bool negative) {
        const detail::SlabInterval& near_cell = negative ? high : low;
        const detail::SlabInterval& far_cell = negative ? low : high;
        const uint32_t near_node = negative ? high_node : low_node, far_node = negative ? low_node : high_node;
        const bool near_hit = detail::slab_hit(near_cell, this->m_cull_t), far_hit = detail::slab_hit(far_cell, this->m_cull_t);
        if (m_short.enabled()) m_short.visit(m_current, m_depth);
        if (near_hit && far_hit) {
            if (this->m_stack_size >= int(kMaxDepth))
                throw Error(std::string(Derived::kName) + " traversal stack overflow (deeper than its image said)");
            m_entry_depth[this->m_stack_size] = m_depth + 1;
            m_stack[this->m_stack_size++] = Entry{far_node, far_cell};
            if (m_short.enabled() && m_short.push()) this->m_work.stack_drops += 1;
        }
        if (near_hit) return go(near_node, near_cell, m_depth + 1);
        if (far_hit) return go(far_node, far_cell, m_depth + 1);
        pop_next();
    }

    /// Pending cells lie behind the current one: those entered beyond the best hit are dropped
    /// without a fetch. With a short stack, reaching an entry it dropped means a restart.
    void pop_next() {
        bool restart = false;
        while (this->m_stack_size > 0) {
            const Entry& e = m_stack[--this->m_stack_size];
            if (m_short.enabled()) restart |= m_short.pop();
            if (e.cell.tn > this->m_cull_t) continue;
            if (restart) return begin_restart(e, true);
            return go(e.node, e.cell, m_entry_depth[this->m_stack_size]);
        }
        if (restart) return begin_restart(Entry{}, false);
        this->finish();
    }

    /// True while a restart's re-descent is being replayed: Derived's execute() then calls
    /// replay_step() instead of its own step.
    bool replaying() const { return m_short.replaying(); }
    /// A revisit re-runs the node's tests to find the way down; the walk's state is unchanged.
    void replay_step() {
        this->m_work.restart_steps += 1;
        this->m_work.restart_box_tests += Derived::kNodeTests;
        m_short.replay_advance();
        if (m_short.replaying()) derived().plan_node(m_short.replay_node());
        else if (m_resume) go(m_resume_entry.node, m_resume_entry.cell, m_resume_depth);
        else this->finish();
    }

    Entry m_stack[kMaxDepth];

private:
    Derived& derived() { return static_cast<Derived&>(*this); }

    void go(uint32_t node, const detail::SlabInterval& cell, uint32_t depth) {
        m_current = node;
        m_depth = depth;
        derived().visit(node, cell);
    }

    void begin_restart(const Entry& e, bool resume) {
        this->m_work.restarts += 1;
        const uint32_t depth = resume ? m_entry_depth[this->m_stack_size] : 0;
        uint32_t first = 0;
        if (Derived::kPushDown && resume) {
            // The shallowest pending entry is the bottom one (a depth-first stack deepens upward).
            const uint32_t shallowest = this->m_stack_size > 0 ? std::min(m_entry_depth[0], depth) : depth;
            first = shallowest > 0 ? shallowest - 1 : 0;
        }
        m_short.restart(depth, uint32_t(this->m_stack_size), first);
        m_resume = resume;
        m_resume_entry = e;
        m_resume_depth = depth;
        derived().plan_node(m_short.replay_node());
    }

    uint32_t m_current = 0;  ///< the node being visited
    uint32_t m_depth = 0;    ///< its depth (root 0)
    uint32_t m_entry_depth[kMaxDepth];
    ShortStack m_short;
    bool m_resume = false;  ///< after the re-descent: m_resume_entry (true) or the end (false)
    Entry m_resume_entry{};
    uint32_t m_resume_depth = 0;
};

}  // namespace rtsim
