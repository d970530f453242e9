#pragma once
// Packets on the BIH (rules in cell_packet.h): the single ray's clip, two clip-plane tests and
// leaf (bih_stepper.h) for each ray of the packet, one node or leaf fetch for all of them.
#include "traces/accel/bih/bih_stepper.h"
#include "traces/accel/cell_packet.h"

namespace rtsim::detail {

struct BihPacketRules {
    using Cell = SlabInterval;
    static constexpr const char* kName = "BIH";
    static constexpr uint32_t kMaxChildren = 2;
    static constexpr uint32_t kMaxStack = kBihMaxDepth;
    static constexpr uint32_t kInteriorTests = BihStepper::kNodeTests;
    static constexpr uint32_t kNodeBytes = sizeof(BihNode);
    static constexpr bool kListLeaves = false;

    BihView view;

    static float entry(const Cell& c) { return c.tn; }
    bool empty() const { return view.node_count == 0; }
    bool clip(const PacketLanes& p, uint32_t r, Cell* cell) const { return clip_root(p, r, view.bounds, cell); }
    uint64_t node_address(uint32_t node) const { return view.node_base + uint64_t(node) * sizeof(BihNode); }
    bool leaf(uint32_t node) const { return view.nodes[node].leaf(); }
    void leaf_span(uint32_t node, uint32_t* first, uint32_t* count) const {
        *first = view.nodes[node].first();
        *count = view.nodes[node].count();
    }
    const HwTriangle* triangles() const { return view.triangles; }
    const TriangleAddressing& tri_at() const { return view.tri_at; }
    /// Slot 0 the left child (ending at clip plane 0), slot 1 the right one (from clip plane 1).
    uint32_t enter(const PacketLanes& p, uint32_t r, uint32_t node, const Cell& cell, uint32_t child[2], Cell cells[2],
                   uint32_t rank[2]) const {
        const BihNode& n = view.nodes[node];
        const int axis = n.axis();
        const bool negative = slab_negative(p.box[r], axis);
        child[0] = n.left(), child[1] = n.left() + 1;
        cells[0] = slab_below(cell, slab_distance(p.box[r], axis, n.clip(0)), negative);
        cells[1] = slab_above(cell, slab_distance(p.box[r], axis, n.clip(1)), negative);
        rank[0] = negative ? 1u : 0u;  // the near child first
        rank[1] = 1u - rank[0];
        return uint32_t(slab_hit(cells[0], p.cull[r])) | uint32_t(slab_hit(cells[1], p.cull[r])) << 1;
    }
};

}  // namespace rtsim::detail
