#pragma once
// Packets on the uniform grid (docs/accel.md, "Packets"). A grid has no stack to share: each ray
// of the packet runs its own conservative 3D-DDA (grid_dda.h) exactly as it would alone, and the
// packet visits the cells its rays reach in lock step. Each step serves, of the cells its rays
// wait at, the first in slice order, with every ray waiting there: slices across the packet's
// major axis (its first ray's largest direction component) in the direction it travels, then
// rows along the second largest, then cells along the third, as Wald, Ize, Kensler, Knoll &
// Parker 2006 ("Ray tracing animated scenes using coherent grid traversal") sweep a packet
// slice by slice. A ray's DDA moves one cell at a time along one axis in its direction, so for
// rays travelling the packet's way the order rises along each ray's path: every ray that will
// visit a cell waits there before the packet passes it, and the rays sharing a cell share its
// fetch. Rays travelling another way are served in the same order, correctly but sharing less. Steps:
//
//   clip   no fetch; every ray tests the grid's bounds (1 box test each)
//   cell   one fetch of the 8-byte GridCell for its rays; 1 cell operation each (their DDA step)
//   list   as the trees' list leaves (packet_lists.h): one fetch of the cell's references, then
//          its windows in lock step, each ray with its own mailbox
//
// A ray goes on to its next cell once it has tested the cell's list (its cull distance as the
// single ray's then), so its cells, tests and hits are the single ray's, and a packet of one ray,
// or of copies of one ray, walks as the single ray. The hybrid's split (cell_packet.h) leaves
// each ray to finish its own DDA alone.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "traces/accel/cell_packet.h"
#include "traces/accel/grid/grid_stepper.h"
#include "traces/isect/ray_box_kernel.h"

namespace rtsim {

class GridPacketWalk final : public Stepper {
public:
    using RulesType = GridView;

    GridPacketWalk(const GridView& view, bool alone) : m_view(view), m_alone(alone) {}

    void bind(PacketLanes* lanes, PacketCounts* counts, Mailbox* mailboxes) {
        m_p = lanes, m_c = counts, m_mail = mailboxes;
    }
    void begin(const Ray&, TraversalMode) override {}  // started by start() or launch()

    void start(float split_below) {
        m_split_below = split_below;
        m_split = false;
        m_serve = ~LaneMask(0);
        m_waiting = 0;
        m_active = m_p->live;
        if (m_active == 0 || m_view.cell_count == 0) return finish();
        set_slice_order(uint32_t(__builtin_ctzll(m_active)));
        m_phase = Phase::clip;
        m_plan.reset(kNoLocality);
        m_plan.add_op(OpKind::box, lane_count(m_active));
        count_step(true);
    }
    /// Ray r's DDA alone after `packet` split, from the cell it was waiting at.
    void launch(uint32_t r, const GridPacketWalk& packet) {
        m_split_below = 0.0f;
        m_split = false;
        m_r = r;
        m_serve = lane_bit(r);
        std::copy(packet.m_axis, packet.m_axis + 3, m_axis);
        std::copy(packet.m_negative, packet.m_negative + 3, m_negative);
        m_dda[r] = packet.m_dda[r];
        m_next[r] = packet.m_next[r];
        m_waiting = packet.m_waiting & m_serve;
        next_cell();
    }

    StepOutcome execute() override {
        StepOutcome out;
        if (m_plan.done) return out;
        PacketLanes& p = *m_p;
        switch (m_phase) {
            case Phase::clip: {
                const Aabb b = m_view.geometry.bounds();
                const float lo[3] = {b.lo.x, b.lo.y, b.lo.z}, hi[3] = {b.hi.x, b.hi.y, b.hi.z};
                for_each_lane(m_active, [&](uint32_t r) {
                    p.work[r].box_tests += 1;
                    float t0;
                    if (!detail::box_kernel(p.box[r], lo, hi, p.ray[r].tmin, p.cull[r], &t0)) return;
                    m_dda[r].begin(m_view.geometry, p.box[r], t0);
                    advance(r);
                });
                next_cell();
                break;
            }
            case Phase::cell: {
                for_each_lane(m_active, [&](uint32_t r) {
                    p.work[r].steps += 1;
                    p.work[r].cell_steps += 1;
                });
                const GridCell& c = m_view.cells[m_cell];
                m_cell_rays = m_active;
                if (c.ref_count == 0) return leave_cell(), out;
                m_lists.open(m_active, m_view.list, c.first_ref, c.ref_count, m_plan);  // its cell's brick
                m_phase = Phase::list;
                count_step(false);
                break;
            }
            case Phase::list:
            case Phase::window:
                if (m_phase == Phase::list) m_lists.arrived(p);
                else out.add_op(OpKind::anyhit, m_lists.test(m_active, m_view.list, p, m_mail));
                next_window();
                break;
        }
        return out;
    }

    LaneMask active() const { return m_plan.done ? 0 : m_active; }
    bool split() const { return m_split; }
    /// The rays left to walk alone after the split: those waiting at a cell.
    LaneMask split_todo() const { return m_waiting & m_p->live; }
    int size() const { return 0; }  // no stack

private:
    enum class Phase : uint8_t { clip, cell, list, window };

    void count_step(bool node_step) {
        m_c->active_rays += lane_count(m_active);
        ++(node_step ? m_c->node_steps : m_c->leaf_steps);
        if (m_alone) ++m_c->split_steps;
    }

    /// Ray r's DDA hands it its next cell (as the single ray's next_cell, with its cull now).
    void advance(uint32_t r) {
        if (m_dda[r].next(m_p->cull[r], &m_next[r])) {
            m_waiting |= lane_bit(r);
        } else {
            m_waiting &= ~lane_bit(r);
        }
    }

    /// The packet's slice order from ray r's direction: axes by falling |direction|, each
    /// walked the way the ray runs along it.
    void set_slice_order(uint32_t r) {
        const Vec3& d = m_p->ray[r].direction;
        const float m[3] = {std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)};
        int a[3] = {0, 1, 2};
        std::sort(a, a + 3, [&](int i, int j) { return m[i] > m[j] || (m[i] == m[j] && i < j); });
        for (int k = 0; k < 3; ++k) m_axis[k] = a[k];
        for (int k = 0; k < 3; ++k) m_negative[k] = std::signbit(k == 0 ? d.x : k == 1 ? d.y : d.z);
    }
    /// A cell's place in the slice order.
    uint64_t slice_key(uint32_t cell) const {
        const GridGeometry& g = m_view.geometry;
        const uint32_t c[3] = {cell % g.res[0], (cell / g.res[0]) % g.res[1], cell / (g.res[0] * g.res[1])};
        uint64_t key = 0;
        for (int k = 0; k < 3; ++k) {
            const int a = m_axis[k];
            key = key * g.res[a] + (m_negative[a] ? g.res[a] - 1 - c[a] : c[a]);
        }
        return key;
    }

    /// The first cell in slice order a ray waits at, with every ray waiting there; the end
    /// when none waits.
    void next_cell() {
        const LaneMask rays = m_waiting & m_p->live & m_serve;
        if (rays == 0) return finish();
        uint32_t cell = 0;
        uint64_t key = 0;
        bool first = true;
        for_each_lane(rays, [&](uint32_t r) {
            const uint64_t k = slice_key(m_next[r]);
            if (first || k < key) cell = m_next[r], key = k, first = false;
        });
        LaneMask at = 0;
        for_each_lane(rays, [&](uint32_t r) {
            if (m_next[r] == cell) at |= lane_bit(r);
        });
        m_cell = cell;
        m_active = at;
        if (!m_alone && detail::should_split(*m_p, at, m_split_below)) {
            m_split = true;
            m_plan.finish();
            return;
        }
        m_phase = Phase::cell;
        m_plan.reset(cell);
        m_plan.add_fetch(m_view.cell_base + uint64_t(cell) * sizeof(GridCell), sizeof(GridCell), DataKind::cell);
        m_plan.add_op(OpKind::cell, lane_count(at));
        count_step(true);
    }

    void next_window() {
        const LaneMask testing = m_lists.plan_window(m_view.list, *m_p, m_mail, m_plan);
        if (testing == 0) return leave_cell();
        m_active = testing;
        m_phase = Phase::window;
        count_step(false);
    }

    /// The cell's rays that are still live go on to their next cells.
    void leave_cell() {
        m_waiting &= ~m_cell_rays;
        for_each_lane(m_cell_rays & m_p->live, [&](uint32_t r) { advance(r); });
        next_cell();
    }

    void finish() {
        if (m_alone && m_p->hit[m_r].prim < 0) m_p->hit[m_r] = Hit{};  // a miss reports the empty hit
        m_active = 0;
        m_plan.finish();
    }

    GridView m_view;
    bool m_alone;
    uint32_t m_r = 0;
    PacketLanes* m_p = nullptr;
    PacketCounts* m_c = nullptr;
    Mailbox* m_mail = nullptr;
    float m_split_below = 0.0f;
    bool m_split = false;
    Phase m_phase = Phase::clip;
    LaneMask m_serve = ~LaneMask(0);  ///< the rays this walk steps (one after a split)
    LaneMask m_waiting = 0;           ///< rays whose DDA has handed them a cell not yet visited
    LaneMask m_active = 0;
    LaneMask m_cell_rays = 0;  ///< the rays in the cell being visited
    uint32_t m_cell = 0;
    int m_axis[3] = {0, 1, 2};                    ///< slice order: the axes, major first
    bool m_negative[3] = {false, false, false};  ///< per axis: the packet walks it downwards
    uint32_t m_next[kMaxPacketLanes];  ///< the cell each waiting ray's DDA handed it
    GridDda m_dda[kMaxPacketLanes];
    PacketLists m_lists;
};

using GridPacketStepper = WalkPacketStepper<GridPacketWalk>;

}  // namespace rtsim
