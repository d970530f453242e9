#pragma once
// Packet traversal rules every tree structure's packet kernel shares (Wald, Slusallek, Benthin &
// Wagner 2001): the shared stack's entry, the leaf step, the pop, and the hybrid's split test
// (Benthin et al. 2012). The node step is each structure's own (bvh2_packet_kernel.h: two
// children; wide/wide_packet_kernel.h: up to eight). Each ray's tests are the single-ray
// kernels' (leaf_kernel.h): a ray's hits never depend on the packet it travels in.
#include <cstdint>
#include <vector>

#include "traces/accel/packet_stepper.h"
#include "traces/common/hw_triangle.h"
#include "traces/isect/leaf_kernel.h"

namespace rtsim::detail {

/// A packet's traversal-stack entry: the child to resume at, its rays, their entry distances.
struct PacketStackEntry {
    uint32_t ref;    ///< node index, or first triangle of a leaf
    uint32_t count;  ///< 0: node; else the leaf's triangle count
    LaneMask mask;
    float tnear[kMaxPacketLanes];
};

/// The packet's leaf step over `active` rays; returns the alpha tests it ran.
inline uint32_t packet_leaf(PacketLanes& p, LaneMask active, const HwTriangle* triangles, uint32_t count) {
    uint32_t alpha = 0;
    const LeafTests kinds = leaf_tests(triangles, count, true);
    for_each_lane(active, [&](uint32_t r) {
        WorkCounts& w = p.work[r];
        count_leaf_tests(w, kinds);
        const uint32_t before = w.anyhit_calls;
        const Ray& ray = p.ray[r];
        if (p.mode[r] == TraversalMode::any_hit) {
            if (leaf_step<true>(p.tri[r], ray.tmin, ray.tmax, triangles, count, p.hit[r], p.cull[r], w.anyhit_calls))
                p.live &= ~lane_bit(r);
        } else {
            leaf_step<false>(p.tri[r], ray.tmin, ray.tmax, triangles, count, p.hit[r], p.cull[r], w.anyhit_calls);
        }
        alpha += w.anyhit_calls - before;
    });
    return alpha;
}

/// Pops the next entry with a ray left in it (its mask in *mask); false when the stack ran out.
inline bool packet_pop(const PacketLanes& p, const PacketStackEntry* stack, int& size, uint32_t* ref,
                       uint32_t* count, LaneMask* mask) {
    while (size > 0) {
        const PacketStackEntry& e = stack[--size];
        LaneMask m = 0;
        // As the single ray's pop: kept unless entered beyond the best hit (a NaN is kept).
        for_each_lane(e.mask & p.live, [&](uint32_t r) {
            if (!(e.tnear[r] > p.cull[r])) m |= lane_bit(r);
        });
        if (m == 0) continue;
        *ref = e.ref;
        *count = e.count;
        *mask = m;
        return true;
    }
    return false;
}

/// True when the packet's step over `active` rays (a node step) should split instead.
inline bool should_split(const PacketLanes& p, LaneMask active, float split_below) {
    return split_below > 0.0f && float(lane_count(active)) < split_below * float(p.n);
}

}  // namespace rtsim::detail

namespace rtsim {

/// A ray walking alone on its lane after its packet split (SplitWalks::lanes): the single-ray
/// rules of a structure (`Rules`, below) on the packet's state for that ray, from its own part of
/// the packet's stack. Its plans are the single ray's (one ray active), counted in the packet's
/// counts as the serial walk counts them (node or leaf step, one active ray, a split step).
///
/// Rules provides: `Entry` (a single-ray stack entry {ref, count, tnear}), `bool descend(lanes,
/// ray, ref, count, stack, size)` (a node step: false when no child is entered), `void
/// plan(StepPlan&, ref, count)` (one ray's step) and `const HwTriangle* leaf(ref)`.
template <class Rules>
class LaneWalker final : public Stepper {
public:
    using Entry = typename Rules::Entry;

    explicit LaneWalker(const Rules& rules, size_t stack_entries) : m_rules(rules), m_stack(stack_entries) {}

    /// Starts ray r at the split: its entries of the shared stack (`mask`, `tnear`, `ref`,
    /// `count` of each), then the packet's node (ref, count) if it was active there.
    template <class Shared>
    void launch(PacketLanes& lanes, PacketCounts& counts, uint32_t r, const Shared* shared, int frozen, bool active,
                uint32_t ref, uint32_t count) {
        m_lanes = &lanes, m_counts = &counts, m_r = r, m_size = 0;
        for (int i = 0; i < frozen; ++i)
            if (shared[i].mask & lane_bit(r)) m_stack[size_t(m_size++)] = Entry{shared[i].ref, shared[i].count, shared[i].tnear[r]};
        m_ref = ref, m_count = count;
        if (active || pop()) plan_next();
        else finish();
    }
    void begin(const Ray&, TraversalMode) override {}  // started by launch()
    StepOutcome execute() override {
        StepOutcome out;
        if (m_plan.done) return out;
        PacketLanes& p = *m_lanes;
        if (m_count == 0) {
            if (m_rules.descend(p, m_r, &m_ref, &m_count, m_stack, m_size)) return plan_next(), out;
        } else {
            out.add_op(OpKind::anyhit, detail::packet_leaf(p, lane_bit(m_r), m_rules.leaf(m_ref), m_count));
        }
        if ((p.live & lane_bit(m_r)) && pop()) plan_next();
        else finish();
        return out;
    }

private:
    bool pop() {
        while (m_size > 0) {
            const Entry& e = m_stack[size_t(--m_size)];
            if (e.tnear > m_lanes->cull[m_r]) continue;  // entered beyond its best hit
            m_ref = e.ref, m_count = e.count;
            return true;
        }
        return false;
    }
    void plan_next() {
        m_counts->active_rays += 1;
        m_counts->split_steps += 1;
        ++(m_count == 0 ? m_counts->node_steps : m_counts->leaf_steps);
        m_rules.plan(m_plan, m_ref, m_count);
        m_stack_size = m_size;
    }
    void finish() {
        Hit& h = m_lanes->hit[m_r];
        if (h.prim < 0) h = Hit{};
        m_plan.finish();
        m_stack_size = 0;
    }

    Rules m_rules;
    PacketLanes* m_lanes = nullptr;
    PacketCounts* m_counts = nullptr;
    uint32_t m_r = 0, m_ref = 0, m_count = 0;
    int m_size = 0;
    std::vector<Entry> m_stack;
};

/// The split with SplitWalks::lanes: every ray of the packet's node (`active` at ref, count) or
/// of the shared stack's `frozen` entries starts its walker; returns the rays whose walkers have
/// steps to take. The other rays' hits are final now (a miss reports the empty hit).
template <class Walker, class Shared>
LaneMask launch_lane_walks(PacketLanes& lanes, PacketCounts& counts, std::vector<Walker>& walkers,
                           const Shared* shared, int frozen, LaneMask active, uint32_t ref, uint32_t count) {
    LaneMask todo = active;
    for (int i = 0; i < frozen; ++i) todo |= shared[i].mask;
    todo &= lanes.live;
    LaneMask walking = 0;
    for_each_lane(todo, [&](uint32_t r) {
        walkers[r].launch(lanes, counts, r, shared, frozen, (active & lane_bit(r)) != 0, ref, count);
        if (!walkers[r].done()) walking |= lane_bit(r);
    });
    for (uint32_t i = 0; i < lanes.n; ++i)
        if (!(walking & lane_bit(i)) && lanes.hit[i].prim < 0) lanes.hit[i] = Hit{};
    return walking;
}

}  // namespace rtsim
