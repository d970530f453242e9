#pragma once
// Packet traversal rules of the wide BVHs, fp32 or compressed (Wald et al. 2001 on nodes of up
// to eight children, as Dammertz, Hanika & Keller 2008 and Ernst & Greiner 2008 trace packets on
// 4-wide BVHs), shared by the packet stepper and the fused packet loop (wide_packet.h) so both
// visit the same nodes in the same order and count the same work. The leaf step, the pop and the
// split test are every tree's (packet_kernel.h); each ray's box tests are the single-ray
// kernel's (wide_kernel.h) on the node decoded once for the packet.
//
//   node:  every active ray tests every child box against its own [tmin, cull] (one box test per
//          child and ray, as a single ray's step); a child is entered when any active ray hits it,
//          with the rays that hit it as its mask. The children entered are ordered as a single
//          ray orders them, on the packet's keys: in distance order by the nearest entry distance
//          among the rays entering each (ties to the lower slot), in octant order by the first
//          active ray's octant. The first is visited next, the others pushed farthest first with
//          their masks and each ray's entry distance. A packet of one ray, or of copies of one
//          ray, thus visits in the single ray's order. With an any-hit order and only any-hit
//          rays active, the children go in that order (the boxes', the same for every ray).
//   split: the hybrid (Benthin et al. 2012): below the threshold the packet stops and its rays
//          finish alone, one after the other in lane order, each from its own part of the shared
//          stack with the single-ray rules of wide_stepper.h (plain stack, fp32 box tests).
#include <cstdint>
#include <vector>

#include "traces/accel/packet_kernel.h"
#include "traces/accel/wide/wide_kernel.h"
#include "traces/common/error.h"

namespace rtsim::detail {

[[noreturn]] inline void throw_wide_packet_overflow(size_t capacity) {
    throw Error("wide BVH: packet traversal stack overflow (" + std::to_string(capacity) + " entries)");
}

/// The children `mask` entered in visit order: by the any-hit order when one applies (the
/// node's boxes, the same for every ray: wide_stepper.h's any-hit order), else by `order` on the
/// entry distances `key` and the octant.
inline int order_entered(uint32_t mask, const float* key, ChildOrder order, uint8_t octant, const DecodedNode& d,
                         AnyHitOrder anyhit, uint8_t slots[kMaxWideWidth]) {
    if (anyhit != AnyHitOrder::nearest) return order_children_anyhit(mask, d, anyhit, slots);
    return order_children(mask, key, order, octant, slots);
}

/// The packet's node step over `active` rays on the decoded node `d`: pushes the children
/// entered after the first onto stack[size..] and names the first in *ref / *count / *mask.
/// Returns false when no active ray hits a child (the caller pops).
inline bool wide_packet_descend(PacketLanes& p, LaneMask active, const DecodedNode& d, ChildOrder order,
                                std::vector<PacketStackEntry>& stack, int& size, uint32_t* ref, uint32_t* count,
                                LaneMask* mask) {
    LaneMask hit[kMaxWideWidth] = {};
    float key[kMaxWideWidth];
    float tn[kMaxWideWidth][kMaxPacketLanes];
    const uint32_t tests = popcount8(d.valid);
    uint32_t entered = 0;
    for_each_lane(active, [&](uint32_t r) {
        p.work[r].steps += 1;
        p.work[r].box_tests += tests;
        float t[kMaxWideWidth];
        const uint32_t m = wide_box_tests(p.box[r], d, p.ray[r].tmin, p.cull[r], t);
        for (uint32_t v = m; v; v &= v - 1) {
            const int s = __builtin_ctz(v);
            tn[s][r] = t[s];
            // The nearest entry; the first ray's own value (even a NaN) when it is the only one.
            if (!(entered >> s & 1u) || t[s] < key[s]) key[s] = t[s];
            hit[s] |= lane_bit(r);
        }
        entered |= m;
    });
    if (entered == 0) return false;
    const uint32_t first = uint32_t(__builtin_ctzll(active));
    uint8_t slots[kMaxWideWidth];
    const int n = order_entered(entered, key, order, ray_octant(p.box[first]), d, p.order_for(active), slots);
    for (int i = n - 1; i >= 1; --i) {
        if (size_t(size) >= stack.size()) throw_wide_packet_overflow(stack.size());
        PacketStackEntry& e = stack[size_t(size++)];
        const int s = slots[i];
        e.ref = d.ref[s];
        e.count = d.count[s];
        e.mask = hit[s];
        for_each_lane(hit[s], [&](uint32_t r) { e.tnear[r] = tn[s][r]; });
    }
    *ref = d.ref[slots[0]];
    *count = d.count[slots[0]];
    *mask = hit[slots[0]];
    return true;
}

/// The hybrid's single-ray walks after a split: the shared stack and the packet's node frozen,
/// the ray walking now and its own stack (sized as the structure's deepest).
struct WideSplitWalk {
    int frozen = 0;               ///< entries of the shared stack at the split
    uint32_t ref = 0, count = 0;  ///< the packet's node at the split
    LaneMask active = 0;          ///< its rays
    LaneMask todo = 0;            ///< rays still to walk alone
    uint32_t ray = 0;             ///< the ray walking now
    int size = 0;
    std::vector<WideStackEntry> stack;

    /// Freezes the packet at its node (ref, count, active) over the shared stack's `n` entries.
    void begin(const PacketLanes& p, const std::vector<PacketStackEntry>& shared, int n, uint32_t at_ref,
               uint32_t at_count, LaneMask at_active) {
        frozen = n;
        ref = at_ref, count = at_count, active = at_active;
        LaneMask t = at_active;
        for (int i = 0; i < n; ++i) t |= shared[size_t(i)].mask;
        todo = t & p.live;
    }

    /// Pops the walking ray's own stack (entries beyond its best hit dropped); false when empty.
    bool pop(const PacketLanes& p, uint32_t* r_ref, uint32_t* r_count) {
        while (size > 0) {
            const WideStackEntry& e = stack[size_t(--size)];
            if (e.tnear > p.cull[ray]) continue;
            *r_ref = e.ref, *r_count = e.count;
            return true;
        }
        return false;
    }

    /// Starts the next ray's walk alone (its node in *r_ref / *r_count); false when none is left.
    bool next_ray(const PacketLanes& p, const std::vector<PacketStackEntry>& shared, uint32_t* r_ref,
                  uint32_t* r_count) {
        while (todo) {
            const uint32_t r = uint32_t(__builtin_ctzll(todo));
            todo &= todo - 1;
            ray = r;
            size = 0;
            for (int i = 0; i < frozen; ++i) {
                const PacketStackEntry& e = shared[size_t(i)];
                if (e.mask & lane_bit(r)) stack[size_t(size++)] = {e.ref, e.count, e.tnear[r]};
            }
            if (active & lane_bit(r)) {
                *r_ref = ref, *r_count = count;
                return true;
            }
            if (pop(p, r_ref, r_count)) return true;
        }
        return false;
    }

    /// One step of the walking ray at (*r_ref, *r_count) with the single-ray rules: node `d` (a
    /// node step) or the leaf's `triangles`. Returns the alpha tests it ran; sets the next step,
    /// false in *more when every ray is done.
    uint32_t step(PacketLanes& p, const DecodedNode* d, ChildOrder order, const HwTriangle* triangles,
                  const std::vector<PacketStackEntry>& shared, uint32_t* r_ref, uint32_t* r_count, bool* more) {
        const uint32_t r = ray;
        uint32_t alpha = 0;
        if (*r_count == 0) {
            WorkCounts& w = p.work[r];
            w.steps += 1;
            w.box_tests += popcount8(d->valid);
            float tnear[kMaxWideWidth];
            const uint32_t mask = wide_box_tests(p.box[r], *d, p.ray[r].tmin, p.cull[r], tnear);
            uint8_t slots[kMaxWideWidth];
            const int n = order_entered(mask, tnear, order, ray_octant(p.box[r]), *d, p.order_of(r), slots);
            if (n > 0) {
                for (int i = n - 1; i >= 1; --i) {
                    if (size_t(size) >= stack.size()) throw_wide_packet_overflow(stack.size());
                    stack[size_t(size++)] = {d->ref[slots[i]], d->count[slots[i]], tnear[slots[i]]};
                }
                *r_ref = d->ref[slots[0]], *r_count = d->count[slots[0]];
                *more = true;
                return 0;
            }
        } else {
            alpha = packet_leaf(p, lane_bit(r), triangles, *r_count);
        }
        *more = ((p.live & lane_bit(r)) && pop(p, r_ref, r_count)) || next_ray(p, shared, r_ref, r_count);
        return alpha;
    }
};

}  // namespace rtsim::detail
