#pragma once
// Packets on the B-Kd tree (rules in cell_packet.h): the single ray's clip, four interval-plane
// tests and leaf (bkd_stepper.h) for each ray of the packet, one node or leaf fetch for all of
// them. As the BIH's rules (bih_packet.h) but for a child's cell cut at both its planes.
#include "traces/accel/bkd/bkd_stepper.h"
#include "traces/accel/cell_packet.h"

namespace rtsim::detail {

struct BkdPacketRules {
    using Cell = SlabInterval;
    static constexpr const char* kName = "B-Kd tree";
    static constexpr uint32_t kMaxChildren = 2;
    static constexpr uint32_t kMaxStack = kBkdMaxDepth;
    static constexpr uint32_t kInteriorTests = BkdStepper::kNodeTests;
    static constexpr uint32_t kNodeBytes = sizeof(BkdNode);
    static constexpr bool kListLeaves = false;

    BkdView view;

    static float entry(const Cell& c) { return c.tn; }
    bool empty() const { return view.node_count == 0; }
    bool clip(const PacketLanes& p, uint32_t r, Cell* cell) const { return clip_root(p, r, view.bounds, cell); }
    uint64_t node_address(uint32_t node) const { return view.node_base + uint64_t(node) * sizeof(BkdNode); }
    bool leaf(uint32_t node) const { return view.nodes[node].leaf(); }
    void leaf_span(uint32_t node, uint32_t* first, uint32_t* count) const {
        *first = view.nodes[node].first();
        *count = view.nodes[node].count();
    }
    const HwTriangle* triangles() const { return view.triangles; }
    const TriangleAddressing& tri_at() const { return view.tri_at; }
    /// Slot 0 the left child, slot 1 the right one, each its parent's cell cut to [lo, hi] on
    /// the node's axis (bkd_stepper.cpp, interior).
    uint32_t enter(const PacketLanes& p, uint32_t r, uint32_t node, const Cell& cell, uint32_t child[2], Cell cells[2],
                   uint32_t rank[2]) const {
        const BkdNode& n = view.nodes[node];
        const int axis = n.axis();
        const bool negative = slab_negative(p.box[r], axis);
        child[0] = n.left(), child[1] = n.left() + 1;
        for (int side = 0; side < 2; ++side) {
            const SlabInterval below = slab_below(cell, slab_distance(p.box[r], axis, n.bound(side, 1)), negative);
            cells[side] = slab_above(below, slab_distance(p.box[r], axis, n.bound(side, 0)), negative);
        }
        rank[0] = negative ? 1u : 0u;  // the near child first
        rank[1] = 1u - rank[0];
        return uint32_t(slab_hit(cells[0], p.cull[r])) | uint32_t(slab_hit(cells[1], p.cull[r])) << 1;
    }
};

}  // namespace rtsim::detail
