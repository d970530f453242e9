#pragma once
// Reference lists walked by a packet's rays in lock step (cell_packet.h, grid_packet.h): one
// fetch of the list for the packet, then the list's windows (ref_list.h) taken by every ray
// together, each ray skipping what its own mailbox holds. A window's step fetches the triangles
// any of its rays tests (at most a window's, so at most a plan's fetches), each ray testing its
// own; a window no ray tests is passed over. A ray alone takes exactly the single ray's windows.
#include <algorithm>
#include <cstdint>

#include "traces/accel/mailbox.h"
#include "traces/accel/packet_stepper.h"
#include "traces/accel/ref_list.h"

namespace rtsim {

class PacketLists {
public:
    /// Plans the fetch of list [first, first + count) (count > 0) for `rays`.
    void open(LaneMask rays, const RefListView& view, uint32_t first, uint32_t count, StepPlan& plan) {
        m_rays = rays;
        // Every ray's walk starts on the same list: the one fetch each plans is the same.
        for_each_lane(rays, [&](uint32_t r) { m_walk[r].plan_list(view, first, count, plan); });
    }
    /// The list arrived: each ray counts its references.
    void arrived(PacketLanes& p) {
        for_each_lane(m_rays, [&](uint32_t r) { m_walk[r].list_fetched(p.work[r]); });
    }
    /// Plans the next window's step; returns the rays testing in it (0: the list is used up, or
    /// every ray left with its hit, and nothing is planned).
    LaneMask plan_window(const RefListView& view, PacketLanes& p, const Mailbox* mail, StepPlan& plan) {
        for (;;) {
            const LaneMask rays = m_rays & p.live;
            if (rays == 0 || !m_walk[__builtin_ctzll(rays)].more()) return 0;
            LaneMask testing = 0;
            uint32_t tris[RefListWalk::kBatch], n = 0, tests = 0;
            for_each_lane(rays, [&](uint32_t r) {
                RefListWalk& w = m_walk[r];
                if (w.take_window(view, mail[r], p.work[r]) == 0) return;
                testing |= lane_bit(r);
                tests += w.batch_size();
                for (uint32_t i = 0; i < w.batch_size(); ++i)
                    if (std::find(tris, tris + n, w.batch()[i]) == tris + n) tris[n++] = w.batch()[i];
            });
            if (testing == 0) continue;  // every ray's mailbox held the window
            plan.reset(kNoLocality);     // the list belongs to its cell's or leaf's treelet
            RefListWalk::add_triangle_fetches(view, tris, n, plan);
            plan.add_op(OpKind::triangle, tests);
            return testing;
        }
    }
    /// The planned window's tests for `testing`; returns the alpha tests run. An any-hit ray
    /// that has its hit leaves the packet.
    uint32_t test(LaneMask testing, const RefListView& view, PacketLanes& p, Mailbox* mail) {
        uint32_t alpha = 0;
        for_each_lane(testing, [&](uint32_t r) {
            bool done = false;
            const Ray& ray = p.ray[r];
            alpha += p.mode[r] == TraversalMode::any_hit
                         ? m_walk[r].test_batch<true>(view, p.tri[r], ray.tmin, ray.tmax, p.hit[r], p.cull[r], mail[r],
                                                      p.work[r], &done)
                         : m_walk[r].test_batch<false>(view, p.tri[r], ray.tmin, ray.tmax, p.hit[r], p.cull[r], mail[r],
                                                       p.work[r], &done);
            if (done) p.live &= ~lane_bit(r);
        });
        return alpha;
    }

private:
    LaneMask m_rays = 0;
    RefListWalk m_walk[kMaxPacketLanes];
};

}  // namespace rtsim
