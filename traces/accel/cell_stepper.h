#pragma once
// What the space-partitioning steppers (grid, kd-tree, BIH, octree; docs/accel.md) share: a ray
// starts with one clip step against the root cell (no fetch, one box test), walks cells front to
// back while its cull distance shrinks, and ends with the empty hit when it found nothing.
// Cells that hold reference lists test them in batches (ref_list.h). The kd-tree and the BIH
// also share their descent: the near child next, the far one pushed with its interval.
#include <cstdint>
#include <string>

#include "traces/accel/mailbox.h"
#include "traces/accel/ref_list.h"
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
/// (a friend of this base) and a kName for the stack-overflow error; Base is CellStepper or, for
/// leaves with reference lists, ListCellStepper.
template <class Derived, uint32_t kMaxDepth, class Base = CellStepper>
class BinaryCellStepper : public Base {
protected:
    struct Entry {
        uint32_t node;
        detail::SlabInterval cell;
    };

    using Base::Base;

    /// The clip step: the ray against the root cell (one box test), then the root node.
    void clip(const Aabb& root) {
        this->m_work.box_tests += 1;
        const float lo[3] = {root.lo.x, root.lo.y, root.lo.z}, hi[3] = {root.hi.x, root.hi.y, root.hi.z};
        const detail::SlabInterval cell = detail::slab_box(this->m_box, lo, hi, this->m_ray.tmin);
        if (!detail::slab_hit(cell, this->m_cull_t)) return this->finish();
        derived().visit(0, cell);
    }

    /// Goes on to the child the ray enters first (`low` when it runs up the split axis), pushing
    /// the other when the ray enters both; pops the next pending cell when it enters neither.
    void descend(uint32_t low_node, const detail::SlabInterval& low, uint32_t high_node,
                 const detail::SlabInterval& high, bool negative) {
        const detail::SlabInterval& near_cell = negative ? high : low;
        const detail::SlabInterval& far_cell = negative ? low : high;
        const uint32_t near_node = negative ? high_node : low_node, far_node = negative ? low_node : high_node;
        const bool near_hit = detail::slab_hit(near_cell, this->m_cull_t), far_hit = detail::slab_hit(far_cell, this->m_cull_t);
        if (near_hit && far_hit) {
            if (this->m_stack_size >= int(kMaxDepth))
                throw Error(std::string(Derived::kName) + " traversal stack overflow (deeper than its image said)");
            m_stack[this->m_stack_size++] = Entry{far_node, far_cell};
        }
        if (near_hit) return derived().visit(near_node, near_cell);
        if (far_hit) return derived().visit(far_node, far_cell);
        pop_next();
    }

    /// Pending cells lie behind the current one: those entered beyond the best hit are dropped
    /// without a fetch.
    void pop_next() {
        while (this->m_stack_size > 0) {
            const Entry& e = m_stack[--this->m_stack_size];
            if (e.cell.tn > this->m_cull_t) continue;
            return derived().visit(e.node, e.cell);
        }
        this->finish();
    }

    Entry m_stack[kMaxDepth];

private:
    Derived& derived() { return static_cast<Derived&>(*this); }
};

}  // namespace rtsim
