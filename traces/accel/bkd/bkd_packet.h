#pragma once
// Packets on the B-Kd tree (rules in cell_packet.h, binary_cell_packet.h): the single ray's
// clip, four interval-plane tests and leaf (bkd_stepper.h) for each ray of the packet, one node
// or leaf fetch for all of them.
#include "traces/accel/bkd/bkd_stepper.h"
#include "traces/accel/binary_cell_packet.h"

namespace rtsim::detail {

struct BkdPacketRules : BinaryCellPacketRules<BkdPacketRules, BkdView, BkdNode> {
    static constexpr const char* kName = "B-Kd tree";
    static constexpr uint32_t kMaxStack = kBkdMaxDepth;
    static constexpr uint32_t kInteriorTests = BkdStepper::kNodeTests;

    /// Each child's cell is its parent's cut to [lo, hi] on the node's axis (bkd_stepper.cpp).
    static void cut(const BkdNode& n, const RayBoxPre& box, int axis, bool negative, const SlabInterval& cell,
                    SlabInterval cells[2]) {
        for (int side = 0; side < 2; ++side) {
            const SlabInterval below = slab_below(cell, slab_distance(box, axis, n.bound(side, 1)), negative);
            cells[side] = slab_above(below, slab_distance(box, axis, n.bound(side, 0)), negative);
        }
    }
};

}  // namespace rtsim::detail
