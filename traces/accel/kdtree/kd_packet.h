#pragma once
// Packets on the kd-tree (Wald, Slusallek, Benthin & Wagner 2001 traced packets on one; rules in
// cell_packet.h): the single ray's clip, plane test and reference lists (kd_stepper.h) for each
// ray of the packet, one node or list fetch for all of them.
#include "traces/accel/cell_packet.h"
#include "traces/accel/kdtree/kd_stepper.h"

namespace rtsim::detail {

struct KdPacketRules {
    using Cell = SlabInterval;
    static constexpr const char* kName = "kd-tree";
    static constexpr uint32_t kMaxChildren = 2;
    static constexpr uint32_t kMaxStack = kKdMaxDepth;
    static constexpr uint32_t kInteriorTests = KdStepper::kNodeTests;
    static constexpr uint32_t kNodeBytes = sizeof(KdNode);
    static constexpr bool kListLeaves = true;

    KdView view;

    static float entry(const Cell& c) { return c.tn; }
    bool empty() const { return view.node_count == 0; }
    bool clip(const PacketLanes& p, uint32_t r, Cell* cell) const { return clip_root(p, r, view.bounds, cell); }
    uint64_t node_address(uint32_t node) const { return view.node_base + uint64_t(node) * sizeof(KdNode); }
    bool leaf(uint32_t node) const { return view.nodes[node].leaf(); }
    void leaf_span(uint32_t node, uint32_t* first, uint32_t* count) const {
        *first = view.nodes[node].first_ref();
        *count = view.nodes[node].ref_count();
    }
    const RefListView& list() const { return view.list; }
    /// Slot 0 the cell below the split plane (the next node), slot 1 the one above.
    uint32_t enter(const PacketLanes& p, uint32_t r, uint32_t node, const Cell& cell, uint32_t child[2], Cell cells[2],
                   uint32_t rank[2]) const {
        const KdNode& n = view.nodes[node];
        const bool negative = slab_negative(p.box[r], n.axis());
        const float t = slab_distance(p.box[r], n.axis(), n.split());
        child[0] = node + 1, child[1] = n.above();
        cells[0] = slab_below(cell, t, negative);
        cells[1] = slab_above(cell, t, negative);
        rank[0] = negative ? 1u : 0u;  // the near child first
        rank[1] = 1u - rank[0];
        return uint32_t(slab_hit(cells[0], p.cull[r])) | uint32_t(slab_hit(cells[1], p.cull[r])) << 1;
    }
};

}  // namespace rtsim::detail
