#pragma once
// Packets on the octree (rules in cell_packet.h): the single ray's clip, three centre-plane tests
// and reference lists (octree_stepper.h) for each ray of the packet, one node or list fetch for
// all of them. A ray's tie order among children is its mirrored child order (child XOR octant).
#include "traces/accel/cell_packet.h"
#include "traces/accel/octree/octree_stepper.h"

namespace rtsim::detail {

struct OctreePacketRules {
    /// A ray's cell: its entry distance and six plane distances (as the single ray's stack entry).
    struct Cell {
        float tn;
        float tlo[3], thi[3];
    };
    static constexpr const char* kName = "octree";
    static constexpr uint32_t kMaxChildren = 8;
    static constexpr uint32_t kMaxStack = kOctMaxStack;
    static constexpr uint32_t kInteriorTests = 3;
    static constexpr uint32_t kNodeBytes = sizeof(OctNode);
    static constexpr bool kListLeaves = true;

    OctView view;

    static float entry(const Cell& c) { return c.tn; }
    static void negative(const PacketLanes& p, uint32_t r, bool out[3]) {
        for (int a = 0; a < 3; ++a) out[a] = slab_negative(p.box[r], a);
    }
    bool empty() const { return view.node_count == 0; }
    bool clip(const PacketLanes& p, uint32_t r, Cell* cell) const {
        bool neg[3];
        negative(p, r, neg);
        for (int a = 0; a < 3; ++a) {
            cell->tlo[a] = slab_distance(p.box[r], a, view.bounds.lo[a]);
            cell->thi[a] = slab_distance(p.box[r], a, view.bounds.hi[a]);
        }
        const SlabInterval s = slab_planes(cell->tlo, cell->thi, neg, p.ray[r].tmin);
        cell->tn = s.tn;
        return slab_hit(s, p.cull[r]);
    }
    uint64_t node_address(uint32_t node) const { return view.node_base + uint64_t(node) * sizeof(OctNode); }
    bool leaf(uint32_t node) const { return view.nodes[node].leaf(); }
    void leaf_span(uint32_t node, uint32_t* first, uint32_t* count) const {
        *first = view.nodes[node].first_ref();
        *count = view.nodes[node].ref_count();
    }
    const RefListView& list() const { return view.list; }
    /// Slot c is child c (x + 2y + 4z); slots of children not stored are never entered.
    uint32_t enter(const PacketLanes& p, uint32_t r, uint32_t node, const Cell& cell, uint32_t child[8], Cell cells[8],
                   uint32_t rank[8]) const {
        const OctNode& n = view.nodes[node];
        bool neg[3];
        negative(p, r, neg);
        uint32_t octant = 0;
        for (int a = 0; a < 3; ++a) octant |= uint32_t(neg[a]) << a;
        float tm[3];
        for (int a = 0; a < 3; ++a) tm[a] = slab_distance(p.box[r], a, n.centre(a));
        uint32_t entered = 0;
        for (uint32_t c = 0; c < 8; ++c) {
            rank[c] = c ^ octant;
            if (!(n.mask() >> c & 1u)) continue;
            child[c] = n.child(c);
            Cell& k = cells[c];
            for (int a = 0; a < 3; ++a) {
                const bool upper = c >> a & 1u;
                k.tlo[a] = upper ? tm[a] : cell.tlo[a];
                k.thi[a] = upper ? cell.thi[a] : tm[a];
            }
            const SlabInterval s = slab_planes(k.tlo, k.thi, neg, p.ray[r].tmin);
            k.tn = s.tn;
            if (slab_hit(s, p.cull[r])) entered |= 1u << c;
        }
        return entered;
    }
};

}  // namespace rtsim::detail
