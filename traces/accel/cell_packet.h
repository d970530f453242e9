#pragma once
// Packets on the space-partitioning trees (kd-tree, BIH, octree; docs/accel.md, "Packets"):
// the rays of a packet share one walk and one stack, as on the BVHs (packet_stepper.h; Wald,
// Slusallek, Benthin & Wagner 2001 built packet tracing on exactly such a kd-tree), each with its
// own interval in the cell the packet is in. Each structure gives its single-ray rules (`Rules`,
// in its folder's *_packet.h), so a ray's tests and its cells are the single ray's:
//
//   clip   no fetch; every active ray tests the root cell (1 box test each); the rays that hit
//          it are the root's.
//   node   one fetch of the node for the packet; an interior node runs the structure's plane
//          tests for every active ray, and a child is entered when any of them enters it, with
//          those rays as its mask and each ray's interval. Children go nearest first by the
//          smallest entry distance of the rays entering them, ties in the order the packet's
//          first active ray would take them (near child first; an octree's mirrored child
//          order), so a packet of one ray, or of copies of one ray, walks as the single ray. The
//          others are pushed, farthest first, with their masks and intervals.
//   list   (kd-tree, octree leaves) one fetch of the leaf's references; then the rays take the
//          list's windows in lock step (ref_list.h), each skipping what its own mailbox holds:
//          one step per window fetches the triangles any active ray tests, each ray testing its
//          own. A window no ray tests is passed over.
//   leaf   (BIH leaves) one fetch of the leaf's triangles, every active ray testing each.
//   pop    an entry's rays that entered it beyond their own best hit are dropped from its mask;
//          an entry left with none is skipped without a fetch. Any-hit rays leave the packet
//          with their hit.
//   split  the hybrid (Benthin et al. 2012): at a node with fewer active rays than the
//          threshold's share, the packet stops and each ray walks on alone from its part of the
//          shared stack, as a packet of itself: one after another on the packet's context, or
//          each on its own lane (SplitWalks::lanes).
//
// The packet's counts: the clip and node steps are node steps, the list, window and leaf steps
// are leaf steps (a window's step may fetch up to 8 triangles, the clip step nothing).
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "traces/accel/mailbox.h"
#include "traces/accel/packet_kernel.h"
#include "traces/accel/packet_stepper.h"
#include "traces/accel/packet_lists.h"
#include "traces/common/aabb.h"
#include "traces/common/error.h"
#include "traces/isect/slab_interval.h"

namespace rtsim {

namespace detail {
/// Ray r's interval in a binary partition's root cell (kd-tree, BIH), as the single ray's clip
/// step computes it (BinaryCellStepper::clip); false when it misses the cell.
inline bool clip_root(const PacketLanes& p, uint32_t r, const Aabb& root, SlabInterval* cell) {
    const float lo[3] = {root.lo.x, root.lo.y, root.lo.z}, hi[3] = {root.hi.x, root.hi.y, root.hi.z};
    *cell = slab_box(p.box[r], lo, hi, p.ray[r].tmin);
    return slab_hit(*cell, p.cull[r]);
}
}  // namespace detail

/// One walk of a packet's rays (or of one ray after a split) through a space-partitioning tree,
/// on lanes, counts and mailboxes it shares with the packet it belongs to.
///
/// Rules provides: `Cell` (a ray's state in a cell: at least its entry distance, `entry(cell)`),
/// kName, kMaxChildren, kMaxStack, kInteriorTests, kListLeaves; `bool empty()`, `bool clip(lanes,
/// r, Cell*)` (ray r against the root cell), `uint64_t node_address(node)`, kNodeBytes, `bool
/// leaf(node)`, `void leaf_span(node, &first, &count)`, `list()` (list leaves) or `triangles()`
/// and `tri_at()` (triangle leaves), and `uint32_t enter(lanes, r, node, cell, child[], cells[],
/// rank[])`: ray r at interior node `node` in `cell`, the children it enters as a bit mask over
/// the node's child slots, each slot's node index, the ray's cell in it and the slot's place in
/// the ray's own order (filled for every slot).
template <class Rules>
class CellPacketWalk final : public Stepper {
public:
    using RulesType = Rules;
    using Cell = typename Rules::Cell;
    struct Entry {
        uint32_t node = 0;
        LaneMask mask = 0;
        Cell cell[kMaxPacketLanes];
    };

    CellPacketWalk(const Rules& rules, bool alone) : m_rules(rules), m_alone(alone) {}

    /// The packet's state this walk steps: its lanes, counts and the rays' mailboxes.
    void bind(PacketLanes* lanes, PacketCounts* counts, Mailbox* mailboxes) {
        m_p = lanes, m_c = counts, m_mail = mailboxes;
    }
    void begin(const Ray&, TraversalMode) override {}  // started by start() or launch()

    /// The packet's walk from the clip step, its threshold for the hybrid's split (0: never).
    void start(float split_below) {
        m_split_below = split_below;
        m_split = false;
        m_size = 0;
        m_active = m_p->live;
        if (m_active == 0 || m_rules.empty()) return finish();
        m_phase = Phase::clip;
        m_plan.reset(kNoLocality);
        m_plan.add_op(OpKind::box, lane_count(m_active));
        count_step(true);
    }
    /// Ray r's walk alone after `packet` split: its part of the shared stack's entries, then the
    /// packet's node if the ray was active there.
    void launch(uint32_t r, const CellPacketWalk& packet) {
        m_split_below = 0.0f;
        m_split = false;
        m_size = 0;
        m_r = r;
        const LaneMask bit = lane_bit(r);
        for (int i = 0; i < packet.m_size; ++i) {
            const Entry& shared = packet.m_stack[size_t(i)];
            if (!(shared.mask & bit)) continue;
            Entry& e = push();
            e.node = shared.node;
            e.mask = bit;
            e.cell[r] = shared.cell[r];
        }
        if (!(m_p->live & bit)) return finish();
        if (packet.split_rays() & bit) {
            m_cell[r] = packet.m_cell[r];
            return go(packet.m_node, bit);
        }
        pop_next();
    }

    StepOutcome execute() override {
        StepOutcome out;
        if (m_plan.done) return out;
        PacketLanes& p = *m_p;
        switch (m_phase) {
            case Phase::clip: {
                LaneMask in = 0;
                for_each_lane(m_active, [&](uint32_t r) {
                    p.work[r].box_tests += 1;
                    if (m_rules.clip(p, r, &m_cell[r])) in |= lane_bit(r);
                });
                if (in == 0) finish();
                else go(0, in);
                break;
            }
            case Phase::node:
                node_step();
                break;
            case Phase::list:
            case Phase::window:
            case Phase::leaf:
                out.add_op(OpKind::anyhit, leaf_step());
                break;
        }
        return out;
    }

    /// The rays of the planned step (0 once done).
    LaneMask active() const { return m_plan.done ? 0 : m_active; }
    /// True when the walk stopped for the hybrid's split: its node, rays and stack are frozen.
    bool split() const { return m_split; }
    /// The rays at the node where it split (0 unless split()).
    LaneMask split_rays() const { return m_split ? m_active : 0; }
    /// The rays left to walk alone after the split: those at its node or in a pending entry.
    LaneMask split_todo() const {
        LaneMask todo = split_rays();
        for (int i = 0; i < m_size; ++i) todo |= m_stack[size_t(i)].mask;
        return todo & m_p->live;
    }
    int size() const { return m_size; }

private:
    enum class Phase : uint8_t { clip, node, list, window, leaf };

    Entry& push() {
        if (m_size >= int(2 * Rules::kMaxStack))
            throw Error(std::string(Rules::kName) + " packet traversal stack overflow (deeper than its image said)");
        if (size_t(m_size) >= m_stack.size()) m_stack.resize(std::max<size_t>(8, 2 * m_stack.size()));
        return m_stack[size_t(m_size++)];
    }

    /// Counts the planned step in the packet's counts (a node step, or a leaf step).
    void count_step(bool node_step) {
        m_c->active_rays += lane_count(m_active);
        ++(node_step ? m_c->node_steps : m_c->leaf_steps);
        if (m_alone) ++m_c->split_steps;
        m_stack_size = m_size;
    }

    /// Plans the node step at `node` for `rays` (their cells in m_cell), or stops for the split.
    void go(uint32_t node, LaneMask rays) {
        m_node = node;
        m_active = rays;
        if (!m_alone && detail::should_split(*m_p, rays, m_split_below)) {
            m_split = true;
            m_plan.finish();
            return;
        }
        m_phase = Phase::node;
        m_plan.reset(node);
        m_plan.add_fetch(m_rules.node_address(node), Rules::kNodeBytes, DataKind::node);
        if (!m_rules.leaf(node)) m_plan.add_op(OpKind::plane, Rules::kInteriorTests * lane_count(rays));
        count_step(true);
    }

    /// A step in a leaf: its list's arrival, a window's tests, or its triangles' tests. Returns
    /// the alpha tests run.
    uint32_t leaf_step() {
        PacketLanes& p = *m_p;
        uint32_t alpha = 0;
        if constexpr (Rules::kListLeaves) {
            if (m_phase == Phase::list) m_lists.arrived(p);
            else alpha = m_lists.test(m_active, m_rules.list(), p, m_mail);
            next_window();
        } else {
            uint32_t first = 0, count = 0;
            m_rules.leaf_span(m_node, &first, &count);
            alpha = detail::packet_leaf(p, m_active, m_rules.triangles() + first, count);
            pop_next();
        }
        return alpha;
    }

    void node_step() {
        PacketLanes& p = *m_p;
        for_each_lane(m_active, [&](uint32_t r) { p.work[r].steps += 1; });
        if (m_rules.leaf(m_node)) return open_leaf();
        // Each ray's children (its plane tests), gathered per child slot.
        LaneMask mask[Rules::kMaxChildren] = {};
        float nearest[Rules::kMaxChildren];
        uint32_t child[Rules::kMaxChildren], rank[Rules::kMaxChildren], lane_rank[Rules::kMaxChildren];
        Cell cells[Rules::kMaxChildren];
        const uint32_t leader = uint32_t(__builtin_ctzll(m_active));
        for_each_lane(m_active, [&](uint32_t r) {
            p.work[r].plane_tests += Rules::kInteriorTests;
            const uint32_t entered = m_rules.enter(p, r, m_node, m_cell[r], child, cells, lane_rank);
            if (r == leader) std::copy(lane_rank, lane_rank + Rules::kMaxChildren, rank);
            for (uint32_t s = 0; s < Rules::kMaxChildren; ++s) {
                if (!(entered >> s & 1u)) continue;
                const float t = Rules::entry(cells[s]);
                if (!mask[s] || t < nearest[s]) nearest[s] = t;
                mask[s] |= lane_bit(r);
                m_child_cell[s][r] = cells[s];
            }
        });
        uint32_t order[Rules::kMaxChildren], n = 0;
        for (uint32_t s = 0; s < Rules::kMaxChildren; ++s)
            if (mask[s]) order[n++] = s;
        if (n == 0) return pop_next();
        // Nearest first by the rays' smallest entry distance, ties in the first ray's order.
        const auto before = [&](uint32_t a, uint32_t b) {
            return nearest[a] != nearest[b] ? nearest[a] < nearest[b] : rank[a] < rank[b];
        };
        for (uint32_t i = 1; i < n; ++i)
            for (uint32_t j = i; j > 0 && before(order[j], order[j - 1]); --j) std::swap(order[j], order[j - 1]);
        for (uint32_t i = n; i-- > 1;) {
            const uint32_t s = order[i];
            Entry& e = push();
            e.node = child[s];
            e.mask = mask[s];
            for_each_lane(mask[s], [&](uint32_t r) { e.cell[r] = m_child_cell[s][r]; });
        }
        const uint32_t s = order[0];
        for_each_lane(mask[s], [&](uint32_t r) { m_cell[r] = m_child_cell[s][r]; });
        go(child[s], mask[s]);
    }

    void open_leaf() {
        uint32_t first = 0, count = 0;
        m_rules.leaf_span(m_node, &first, &count);
        if (count == 0) return pop_next();
        if constexpr (Rules::kListLeaves) {
            m_lists.open(m_active, m_rules.list(), first, count, m_plan);
            m_phase = Phase::list;
        } else {
            m_plan.reset(kNoLocality);  // a leaf's triangles belong to its node's treelet
            const TriangleAddressing::Span span = m_rules.tri_at().span(first, count);
            m_plan.add_fetch(span.address, span.bytes, DataKind::triangle);
            m_plan.add_leaf_ops(detail::leaf_tests(m_rules.triangles() + first, count, true), lane_count(m_active));
            m_phase = Phase::leaf;
        }
        count_step(false);
    }

    /// The leaf's rays take the list's next window together (packet_lists.h); pops when the
    /// list is used up or every ray left with its hit.
    void next_window() {
        if constexpr (Rules::kListLeaves) {
            const LaneMask testing = m_lists.plan_window(m_rules.list(), *m_p, m_mail, m_plan);
            if (testing == 0) return pop_next();
            m_active = testing;
            m_phase = Phase::window;
            count_step(false);
        }
    }

    /// Goes on to the next pending entry with a ray left in it.
    void pop_next() {
        const PacketLanes& p = *m_p;
        while (p.live && m_size > 0) {
            const Entry& e = m_stack[size_t(--m_size)];
            LaneMask m = 0;
            // As the single ray's pop: dropped when entered beyond its best hit.
            for_each_lane(e.mask & p.live, [&](uint32_t r) {
                if (!(Rules::entry(e.cell[r]) > p.cull[r])) m |= lane_bit(r);
            });
            if (m == 0) continue;
            for_each_lane(m, [&](uint32_t r) { m_cell[r] = e.cell[r]; });
            return go(e.node, m);
        }
        finish();
    }

    void finish() {
        if (m_alone && m_p->hit[m_r].prim < 0) m_p->hit[m_r] = Hit{};  // a miss reports the empty hit
        m_active = 0;
        m_size = 0;
        m_stack_size = 0;
        m_plan.finish();
    }

    Rules m_rules;
    bool m_alone;      ///< a ray walking alone after a split: its steps are split steps
    uint32_t m_r = 0;  ///< that ray
    PacketLanes* m_p = nullptr;
    PacketCounts* m_c = nullptr;
    Mailbox* m_mail = nullptr;
    float m_split_below = 0.0f;
    bool m_split = false;
    Phase m_phase = Phase::clip;
    uint32_t m_node = 0;
    LaneMask m_active = 0;
    int m_size = 0;
    std::vector<Entry> m_stack;
    Cell m_cell[kMaxPacketLanes];
    Cell m_child_cell[Rules::kMaxChildren][kMaxPacketLanes];
    PacketLists m_lists;
};

/// A packet stepper over a packet walk (`Walk`: CellPacketWalk, GridPacketWalk): the packet's
/// walk, and its rays' walks alone after the hybrid's split, each a Walk of one ray on the
/// packet's lanes (Walk::launch(r, packet)).
template <class Walk>
class WalkPacketStepper final : public PacketStepper {
public:
    using Rules = typename Walk::RulesType;

    WalkPacketStepper(const Rules& rules, uint32_t mailbox_entries) : m_rules(rules), m_walk(rules, false) {
        for (Mailbox& m : m_mail) m.set_entries(mailbox_entries);
        m_walk.bind(&m_lanes, &m_counts, m_mail);
    }

    void begin_packet(const Ray* rays, const TraversalMode* modes, uint32_t n) override {
        start_packet(rays, modes, n);
        for (uint32_t i = 0; i < n; ++i) m_mail[i].clear();
        m_serial = false;
        m_walk.start(m_split_below);
        follow(m_walk);
    }

    StepOutcome execute() override {
        if (m_plan.done) return StepOutcome{};
        if (m_serial) {
            Walk& w = walker(m_serial_ray);
            const StepOutcome out = w.execute();
            if (w.done()) next_serial_ray();
            else follow(w);
            return out;
        }
        const StepOutcome out = m_walk.execute();
        follow(m_walk);
        return out;
    }

    Stepper& lane_walker(uint32_t i) override { return walker(i); }

private:
    Walk& walker(uint32_t r) {
        if (m_walkers.empty()) {
            m_walkers.reserve(kMaxPacketLanes);
            for (uint32_t i = 0; i < kMaxPacketLanes; ++i) {
                m_walkers.emplace_back(m_rules, true);
                m_walkers.back().bind(&m_lanes, &m_counts, m_mail);
            }
        }
        return m_walkers[r];
    }

    /// Mirrors `w`'s planned step as the packet's; the walk's end or split ends the packet's.
    void follow(const Walk& w) {
        if (&w == &m_walk && w.split()) return split();
        if (w.done()) return end_packet();
        m_plan = w.plan();
        m_active = w.active();
        m_stack_size = w.size();
    }

    void split() {
        ++m_counts.splits;
        const LaneMask todo = m_walk.split_todo();
        if (m_split_walks == SplitWalks::lanes) {
            LaneMask walking = 0;
            for_each_lane(todo, [&](uint32_t r) {
                walker(r).launch(r, m_walk);
                if (!walker(r).done()) walking |= lane_bit(r);
            });
            for (uint32_t i = 0; i < m_lanes.n; ++i)
                if (!(walking & lane_bit(i)) && m_lanes.hit[i].prim < 0) m_lanes.hit[i] = Hit{};
            m_split_lanes = walking;
            m_active = 0;
            m_stack_size = 0;
            m_plan.finish();
            return;
        }
        m_serial = true;
        m_todo = todo;
        next_serial_ray();
    }

    void next_serial_ray() {
        while (m_todo) {
            const uint32_t r = uint32_t(__builtin_ctzll(m_todo));
            m_todo &= m_todo - 1;
            walker(r).launch(r, m_walk);
            if (walker(r).done()) continue;
            m_serial_ray = r;
            return follow(walker(r));
        }
        end_packet();
    }

    Rules m_rules;
    Walk m_walk;
    std::vector<Walk> m_walkers;  ///< one per lane, made at the first split
    Mailbox m_mail[kMaxPacketLanes];
    bool m_serial = false;  ///< split: the rays walk alone one after another (m_serial_ray now)
    uint32_t m_serial_ray = 0;
    LaneMask m_todo = 0;  ///< rays still to walk alone
};

/// The packet stepper of a space-partitioning tree.
template <class Rules>
using CellPacketStepper = WalkPacketStepper<CellPacketWalk<Rules>>;

}  // namespace rtsim
