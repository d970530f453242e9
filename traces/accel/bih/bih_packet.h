#pragma once
// Packets on the BIH (rules in cell_packet.h, binary_cell_packet.h): the single ray's clip, two
// clip-plane tests and leaf (bih_stepper.h) for each ray of the packet, one node or leaf fetch
// for all of them.
#include "traces/accel/bih/bih_stepper.h"
#include "traces/accel/binary_cell_packet.h"

namespace rtsim::detail {

struct BihPacketRules : BinaryCellPacketRules<BihPacketRules, BihView, BihNode> {
    static constexpr const char* kName = "BIH";
    static constexpr uint32_t kMaxStack = kBihMaxDepth;
    static constexpr uint32_t kInteriorTests = BihStepper::kNodeTests;

    /// The left child's cell ends at clip plane 0, the right one's starts at clip plane 1.
    static void cut(const BihNode& n, const RayBoxPre& box, int axis, bool negative, const SlabInterval& cell,
                    SlabInterval cells[2]) {
        cells[0] = slab_below(cell, slab_distance(box, axis, n.clip(0)), negative);
        cells[1] = slab_above(cell, slab_distance(box, axis, n.clip(1)), negative);
    }
};

}  // namespace rtsim::detail
