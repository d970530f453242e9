#pragma once
// A cell's or leaf's list of primitive references, tested in steps of gathered triangles (the
// grid, the kd-tree and the octree share it; docs/accel.md). The list itself is one contiguous
// read of 4-byte triangle indices (counted as `refs`); then each step gathers up to kBatch listed
// triangles (one 48-byte fetch each) and runs one triangle test each. With a mailbox
// (mailbox.h), references the ray has already tested are skipped before their fetch: counted as
// mailbox lookups and hits, never fetched or tested.
#include <algorithm>
#include <cstdint>

#include "traces/accel/leaf_blocks.h"
#include "traces/accel/mailbox.h"
#include "traces/accel/step_plan.h"
#include "traces/common/hw_triangle.h"
#include "traces/isect/leaf_kernel.h"

namespace rtsim {

/// Where the reference lists and the triangles they index live.
struct RefListView {
    const uint32_t* refs = nullptr;
    const HwTriangle* triangles = nullptr;
    uint64_t ref_base = 0;     ///< address of reference 0
    TriangleAddressing tri_at; ///< where triangles' bytes are (plain or compressed leaves)
};

/// Bytes of one reference (a uint32 triangle index).
constexpr uint32_t kRefBytes = 4;

class RefListWalk {
public:
    static constexpr uint32_t kBatch = StepPlan::kMaxFetches;

    /// Plans the fetch of list [first, first + count) (count > 0).
    void plan_list(const RefListView& v, uint32_t first, uint32_t count, StepPlan& plan) {
        m_first = first;
        m_count = count;
        m_next = 0;
        plan.reset(kNoLocality);  // the list belongs to its cell's or leaf's treelet
        plan.add_fetch(v.ref_base + uint64_t(first) * kRefBytes, count * kRefBytes, DataKind::prim_ref);
    }
    /// The list arrived: counts its references.
    void list_fetched(WorkCounts& work) const { work.refs += m_count; }

    /// Plans the next step's triangles: the list's next window of up to kBatch entries, less those
    /// the mailbox holds (a window the mailbox holds whole is passed over). The windows are the
    /// same with a mailbox or without, so an any-hit ray stops in the same window and the
    /// tests counted plus the mailbox hits equal the tests counted without one. False (the plan
    /// untouched) when the list is used up.
    bool plan_batch(const RefListView& v, const Mailbox& mailbox, WorkCounts& work, StepPlan& plan) {
        m_batch_size = 0;
        while (m_batch_size == 0 && more()) take_window(v, mailbox, work);
        if (m_batch_size == 0) return false;
        plan.reset(kNoLocality);
        add_triangle_fetches(v, m_batch, m_batch_size, plan);
        plan.add_op(OpKind::triangle, m_batch_size);
        return true;
    }

    /// True while the list has windows left.
    bool more() const { return m_next < m_count; }
    /// Takes the list's next window as the batch (the mailbox's lookups and hits counted), which
    /// may be empty when the mailbox holds it whole. Packets take windows in lock step with it
    /// (cell_packet.h); plan_batch() is this until a window has triangles.
    uint32_t take_window(const RefListView& v, const Mailbox& mailbox, WorkCounts& work) {
        m_batch_size = 0;
        const uint32_t end = std::min(m_count, m_next + kBatch);
        for (; m_next < end; ++m_next) {
            const uint32_t tri = v.refs[m_first + m_next];
            if (mailbox.enabled()) {
                work.mailbox_lookups += 1;
                if (mailbox.contains(tri)) {
                    work.mailbox_hits += 1;
                    continue;
                }
            }
            m_batch[m_batch_size++] = tri;
        }
        return m_batch_size;
    }
    /// The batch taken: triangle indices in list order.
    const uint32_t* batch() const { return m_batch; }
    uint32_t batch_size() const { return m_batch_size; }
    /// One fetch per triangle of tris[0, n), in that order.
    static void add_triangle_fetches(const RefListView& v, const uint32_t* tris, uint32_t n, StepPlan& plan) {
        for (uint32_t i = 0; i < n; ++i) {
            const TriangleAddressing::Span s = v.tri_at.span(tris[i], 1);
            plan.add_fetch(s.address, s.bytes, DataKind::triangle);
        }
    }

    /// Tests the planned triangles against the ray's own [tmin, tmax] (the shared hit rules) and
    /// records each in the mailbox unless its alpha test rejected it. Returns the alpha tests run;
    /// *done is set when an any-hit ray has its hit.
    template <bool kAnyHit>
    uint32_t test_batch(const RefListView& v, const RayTrianglePre& pre, float tmin, float tmax, Hit& best,
                        float& cull_t, Mailbox& mailbox, WorkCounts& work, bool* done) {
        const uint32_t alpha_before = work.anyhit_calls;
        work.tri_tests += m_batch_size;
        *done = false;
        for (uint32_t i = 0; i < m_batch_size && !*done; ++i) {
            const uint32_t calls = work.anyhit_calls;
            const bool taken =
                detail::triangle_step<kAnyHit>(pre, tmin, tmax, v.triangles[m_batch[i]], best, cull_t, work.anyhit_calls);
            *done = kAnyHit && taken;
            const bool alpha_rejected = work.anyhit_calls != calls && !taken;
            if (mailbox.enabled() && !alpha_rejected) mailbox.insert(m_batch[i]);
        }
        return work.anyhit_calls - alpha_before;
    }

private:
    uint32_t m_first = 0, m_count = 0, m_next = 0;
    uint32_t m_batch_size = 0;
    uint32_t m_batch[kBatch];
};

}  // namespace rtsim
