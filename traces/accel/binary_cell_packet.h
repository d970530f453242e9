#pragma once
// Packet rules (cell_packet.h) shared by the binary interval trees, the BIH and the B-Kd tree:
// two children per node on one axis, triangles stored contiguously in the leaves. A structure
// gives its name, depth and plane tests, and how a child's cell is cut from its parent's
// (`Derived::cut`); everything else is the same walk over the same view layout.
#include "traces/accel/cell_packet.h"

namespace rtsim::detail {

template <class Derived, class View, class Node>
struct BinaryCellPacketRules {
    using Cell = SlabInterval;
    static constexpr uint32_t kMaxChildren = 2;
    static constexpr uint32_t kNodeBytes = sizeof(Node);
    static constexpr bool kListLeaves = false;

    View view;

    static float entry(const Cell& c) { return c.tn; }
    bool empty() const { return view.node_count == 0; }
    bool clip(const PacketLanes& p, uint32_t r, Cell* cell) const { return clip_root(p, r, view.bounds, cell); }
    uint64_t node_address(uint32_t node) const { return view.node_base + uint64_t(node) * sizeof(Node); }
    bool leaf(uint32_t node) const { return view.nodes[node].leaf(); }
    void leaf_span(uint32_t node, uint32_t* first, uint32_t* count) const {
        *first = view.nodes[node].first();
        *count = view.nodes[node].count();
    }
    const HwTriangle* triangles() const { return view.triangles; }
    const TriangleAddressing& tri_at() const { return view.tri_at; }
    /// Slot 0 the left child, slot 1 the right one, each cell cut by the structure's rule.
    uint32_t enter(const PacketLanes& p, uint32_t r, uint32_t node, const Cell& cell, uint32_t child[2], Cell cells[2],
                   uint32_t rank[2]) const {
        const Node& n = view.nodes[node];
        const int axis = n.axis();
        const bool negative = slab_negative(p.box[r], axis);
        child[0] = n.left(), child[1] = n.left() + 1;
        Derived::cut(n, p.box[r], axis, negative, cell, cells);
        rank[0] = negative ? 1u : 0u;  // the near child first
        rank[1] = 1u - rank[0];
        return uint32_t(slab_hit(cells[0], p.cull[r])) | uint32_t(slab_hit(cells[1], p.cull[r])) << 1;
    }
};

}  // namespace rtsim::detail
