#pragma once
// Packet traversal rules of the binary BVH (Wald, Slusallek, Benthin & Wagner 2001), shared by
// its packet stepper and its fused packet loop (bvh2_packet.cpp) so both visit the same nodes in
// the same order and count the same work. Each ray's tests are the single-ray kernel's
// (bvh2_kernel.h, leaf_kernel.h): a ray's hits never depend on the packet it travels in.
//
//   node:  every active ray tests both child boxes against its own [tmin, cull]; a child is
//          entered when any active ray hits it, with the rays that hit it as its active mask.
//          When both are entered, the packet goes first to the child most of the rays hitting
//          both enter first (child 0 on a tie); the other is pushed with its mask and each
//          ray's entry distance. A packet of one ray thus visits in the single ray's order.
//          With an any-hit order (traversal.anyhit_order) and only any-hit rays active, the
//          packet goes first to the child that order picks (larger box, or child 0): the
//          order is the node's, the same for every ray, so a shadow packet keeps it whole.
//   leaf:  every active ray tests the leaf's triangles; an any-hit ray that found its hit
//          leaves the packet.
//   pop:   an entry's rays whose entry distance lies beyond their own (widened) best hit are
//          dropped from its mask; an entry left with none is skipped without a fetch.
//   split: the hybrid (Benthin, Wald, Woop, Ernst & Mark 2012, "Combining single and packet-ray
//          tracing for arbitrary ray distributions on the Intel MIC architecture"): when fewer
//          than a fraction of the packet's rays are active at a node, the packet stops and its
//          rays finish alone, one after the other in lane order, each from its own part of the
//          shared stack (the entries whose mask holds it, with its entry distances) with the
//          single-ray rules. Each ray's hits are still its single-ray hits.
#include <cstdint>

#include "traces/accel/bvh2/bvh2_kernel.h"
#include "traces/accel/bvh2/bvh2_stepper.h"
#include "traces/accel/packet_kernel.h"

namespace rtsim::detail {

/// The packet's node step over `active` rays at node `at` of `view`: pushes the second child
/// entered onto stack[size++] and names the first in *ref / *count / *mask. Returns false when no
/// active ray hits a child (the caller pops). An oriented node (obvh2) is tested by each ray
/// rotated into its frame, as a single ray tests it (one obb rotation per active ray).
inline bool packet_descend(PacketLanes& p, LaneMask active, const Bvh2View& view, uint32_t at, PacketStackEntry* stack,
                           int& size, uint32_t* ref, uint32_t* count, LaneMask* mask) {
    const HwNode& node = view.nodes[at];
    const bool oriented = view.oriented(at);
    LaneMask hit[2] = {0, 0};
    float tn[2][kMaxPacketLanes];
    uint32_t both = 0, far_first = 0;  // rays hitting both children; those entering child 1 first
    for_each_lane(active, [&](uint32_t r) {
        p.work[r].steps += 1;
        p.work[r].box_tests += 2;
        float t[2];
        unsigned m;
        if (oriented) {
            p.work[r].obb_rotations += 1;
            const OrientedNode o = oriented_node(view, at, p.ray[r], obb_pad(p.ray[r].origin, view.scene_radius));
            m = node_step(o.pre, o.node, p.ray[r].tmin, p.cull[r], t);
        } else {
            m = node_step(p.box[r], node, p.ray[r].tmin, p.cull[r], t);
        }
        tn[0][r] = t[0];
        tn[1][r] = t[1];
        if (m & 1u) hit[0] |= lane_bit(r);
        if (m & 2u) hit[1] |= lane_bit(r);
        if (m == 3u) ++both, far_first += next_slot(m, t);
    });
    if ((hit[0] | hit[1]) == 0) return false;
    const AnyHitOrder order = p.order_for(active);
    const unsigned next = !hit[0]                          ? 1u
                          : !hit[1]                        ? 0u
                          : order != AnyHitOrder::nearest ? next_slot(3u, nullptr, node, order)
                                                           : (2 * far_first > both ? 1u : 0u);
    if (hit[0] && hit[1]) {
        const unsigned far = next ^ 1u;
        if (size >= kTraversalStackSize) throw_stack_overflow();
        PacketStackEntry& e = stack[size++];
        e.ref = node.child_ref[far];
        e.count = node.child_count[far];
        e.mask = hit[far];
        for_each_lane(hit[far], [&](uint32_t r) { e.tnear[r] = tn[far][r]; });
    }
    *ref = node.child_ref[next];
    *count = node.child_count[next];
    *mask = hit[next];
    return true;
}

/// The hybrid's single-ray walks after a split: the shared stack and the packet's node frozen,
/// the ray walking now and its own stack.
struct SplitWalk {
    int frozen = 0;             ///< entries of the shared stack at the split
    uint32_t ref = 0, count = 0;  ///< the packet's node at the split
    LaneMask active = 0;        ///< its rays
    LaneMask todo = 0;          ///< rays still to walk alone
    uint32_t ray = 0;           ///< the ray walking now
    int size = 0;
    Bvh2StackEntry stack[kTraversalStackSize];
};

/// Freezes the packet at its node (ref, count, active) over the shared stack's `size` entries.
inline void begin_split(const PacketLanes& p, const PacketStackEntry* shared, int size, uint32_t ref, uint32_t count,
                        LaneMask active, SplitWalk& s) {
    s.frozen = size;
    s.ref = ref, s.count = count, s.active = active;
    LaneMask todo = active;
    for (int i = 0; i < size; ++i) todo |= shared[i].mask;
    s.todo = todo & p.live;
}

/// Pops ray s.ray's own stack (entries beyond its best hit dropped); false when it is empty.
inline bool split_pop(const PacketLanes& p, SplitWalk& s, uint32_t* ref, uint32_t* count) {
    while (s.size > 0) {
        const Bvh2StackEntry& e = s.stack[--s.size];
        if (e.tnear > p.cull[s.ray]) continue;
        *ref = e.ref, *count = e.count;
        return true;
    }
    return false;
}

/// Starts the next ray's walk alone (its node in *ref / *count); false when none is left.
inline bool split_next_ray(const PacketLanes& p, const PacketStackEntry* shared, SplitWalk& s, uint32_t* ref,
                           uint32_t* count) {
    while (s.todo) {
        const uint32_t r = uint32_t(__builtin_ctzll(s.todo));
        s.todo &= s.todo - 1;
        s.ray = r;
        s.size = 0;
        for (int i = 0; i < s.frozen; ++i)
            if (shared[i].mask & lane_bit(r)) s.stack[s.size++] = {shared[i].ref, shared[i].count, shared[i].tnear[r]};
        if (s.active & lane_bit(r)) {
            *ref = s.ref, *count = s.count;
            return true;
        }
        if (split_pop(p, s, ref, count)) return true;
    }
    return false;
}

/// One step of ray s.ray alone at (ref, count): the single-ray node or leaf step. Returns the
/// alpha tests it ran; sets *ref / *count to its next step, false in *more when every ray is done.
/// Ray r's single-ray node step at node `at` of `view` (rotated into an oriented node's frame).
inline bool lane_descend(PacketLanes& p, uint32_t r, const Bvh2View& view, uint32_t* ref, uint32_t* count,
                         Bvh2StackEntry* stack, int& size) {
    const uint32_t at = *ref;
    if (!view.oriented(at))
        return descend(p.box[r], view.nodes[at], p.ray[r].tmin, p.cull[r], p.work[r], stack, size, ref, count,
                       p.order_of(r));
    p.work[r].obb_rotations += 1;
    const OrientedNode o = oriented_node(view, at, p.ray[r], obb_pad(p.ray[r].origin, view.scene_radius));
    return descend(o.pre, o.node, p.ray[r].tmin, p.cull[r], p.work[r], stack, size, ref, count, p.order_of(r));
}

inline uint32_t split_step(PacketLanes& p, const Bvh2View& view, const PacketStackEntry* shared, SplitWalk& s,
                           uint32_t* ref, uint32_t* count, bool* more) {
    const uint32_t r = s.ray;
    uint32_t alpha = 0;
    if (*count == 0) {
        if (lane_descend(p, r, view, ref, count, s.stack, s.size)) {
            *more = true;
            return 0;
        }
    } else {
        alpha = packet_leaf(p, lane_bit(r), view.triangles + *ref, *count);
    }
    *more = ((p.live & lane_bit(r)) && split_pop(p, s, ref, count)) || split_next_ray(p, shared, s, ref, count);
    return alpha;
}

}  // namespace rtsim::detail
