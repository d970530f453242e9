#pragma once
// A PacketStepper walks a packet of rays through one acceleration structure together, one packet
// step at a time (Wald, Slusallek, Benthin & Wagner 2001, "Interactive rendering with coherent
// ray tracing"): the rays share one traversal stack, a node is entered when any active ray hits
// its box, and an active mask says which rays take part in each step. It is a Stepper whose
// plan() is the packet's step: one fetch of the node (or leaf triangles) serves every active ray,
// and its operations are the active rays' tests together, so whoever times single-ray plans
// times packet steps with the same step-demand function.
//
//   begin_packet(rays, modes, n);
//   while (!plan().done) { ...fetch plan().fetch[], then... execute(); }
//   lane_hit(i), lane_work(i), counts()
//
// A ray's work counts are the steps it was active in (node steps, its box and triangle tests),
// so a packet of one ray, or of copies of one ray, does each ray's single-ray work exactly.
#include <cstdint>

#include "traces/accel/step_options.h"
#include "traces/accel/stepper.h"
#include "traces/isect/ray_box.h"
#include "traces/isect/ray_triangle.h"

namespace rtsim {

/// Widest packet a stepper takes (one bit per ray in a LaneMask).
constexpr uint32_t kMaxPacketLanes = 64;
using LaneMask = uint64_t;

inline LaneMask lane_bit(uint32_t i) { return LaneMask(1) << i; }
inline uint32_t lane_count(LaneMask m) { return uint32_t(__builtin_popcountll(m)); }
/// Calls f(i) for every set bit i of m, lowest first.
template <class F>
inline void for_each_lane(LaneMask m, F&& f) {
    while (m) {
        f(uint32_t(__builtin_ctzll(m)));
        m &= m - 1;
    }
}

/// What a packet's walk did as a whole (the per-ray work is each ray's WorkCounts).
struct PacketCounts {
    uint64_t node_steps = 0;   ///< packet steps that fetched a node (one fetch for the packet)
    uint64_t leaf_steps = 0;   ///< packet steps that fetched a leaf's triangles
    uint64_t active_rays = 0;  ///< active rays summed over the packet steps
    uint64_t split_steps = 0;  ///< of these steps, those of single rays after the packet split (hybrid)
    uint64_t splits = 0;       ///< 1 if the packet split (hybrid)
    bool operator==(const PacketCounts& o) const {
        return node_steps == o.node_steps && leaf_steps == o.leaf_steps && active_rays == o.active_rays &&
               split_steps == o.split_steps && splits == o.splits;
    }
    PacketCounts& operator+=(const PacketCounts& o) {
        node_steps += o.node_steps, leaf_steps += o.leaf_steps, active_rays += o.active_rays;
        split_steps += o.split_steps, splits += o.splits;
        return *this;
    }
};

/// The per-ray state of a packet: rays, their precomputed tests, best hits, cull distances, work.
struct PacketLanes {
    uint32_t n = 0;
    LaneMask live = 0;  ///< rays still traversing: valid, and (any-hit) not yet done
    Ray ray[kMaxPacketLanes];
    TraversalMode mode[kMaxPacketLanes];
    RayBoxPre box[kMaxPacketLanes];
    RayTrianglePre tri[kMaxPacketLanes];
    float cull[kMaxPacketLanes];  ///< boxes entered beyond this are culled: best t widened
    Hit hit[kMaxPacketLanes];     ///< best hit so far (t: the shrinking tmax)
    WorkCounts work[kMaxPacketLanes];
    /// Child order of the packet's any-hit rays (StepOptions::anyhit_order), kept across begin().
    AnyHitOrder anyhit_order = AnyHitOrder::nearest;

    /// The order of a node step over `active` rays: the any-hit order when every one of them is
    /// an any-hit ray (a shadow packet: the order is the boxes', the same for every ray), else
    /// nearest first (a closest-hit ray among them must not trade its order for another's).
    AnyHitOrder order_for(LaneMask active) const {
        if (anyhit_order == AnyHitOrder::nearest) return anyhit_order;
        for (LaneMask m = active; m; m &= m - 1)
            if (mode[__builtin_ctzll(m)] != TraversalMode::any_hit) return AnyHitOrder::nearest;
        return anyhit_order;
    }
    /// Ray r's own order when it walks alone after a split (its single-ray stepper's).
    AnyHitOrder order_of(uint32_t r) const {
        return mode[r] == TraversalMode::any_hit ? anyhit_order : AnyHitOrder::nearest;
    }

    /// Starts the packet (n <= kMaxPacketLanes; throws rtsim::Error otherwise). Invalid rays are
    /// never live: a miss, no work.
    void begin(const Ray* rays, const TraversalMode* modes, uint32_t count);
    /// Rays without a hit report Hit{} (t = +inf).
    void finish();
};

/// How the hybrid's rays walk after their packet split (Benthin et al. 2012).
enum class SplitWalks : uint8_t {
    serial = 0,  ///< one after another in lane order, on the packet's context (its plan)
    lanes = 1,   ///< each on its own lane of the packet, all at once (lane_walker())
};

class PacketStepper : public Stepper {
public:
    virtual void begin_packet(const Ray* rays, const TraversalMode* modes, uint32_t n) = 0;
    /// The hybrid (Benthin et al. 2012): from the next packet on, a packet whose active rays at a
    /// node are fewer than `fraction` of its rays splits, and they finish as single rays (0: never).
    void set_split_below(float fraction) { m_split_below = fraction; }
    /// How split rays walk, from the next packet on. With SplitWalks::lanes the packet's plan is
    /// done at the split, and each ray of split_lanes() walks alone as lane_walker(i): a Stepper
    /// of its own (plan, execute, stack) that whoever drives the packet drives on ray i's lane.
    /// Every ray's hit and work are the serial walk's (each walk is the ray's alone); the
    /// packet's lane_hit(i) / lane_work(i) and counts() are final once every walker is done.
    void set_split_walks(SplitWalks walks) { m_split_walks = walks; }
    /// Child order of any-hit rays (StepOptions::anyhit_order) from the next packet on, on the
    /// structures whose packet kernels offer it (AccelCapabilities::anyhit_order).
    void set_anyhit_order(AnyHitOrder order) { m_lanes.anyhit_order = order; }
    /// The rays walking alone after a split with SplitWalks::lanes (0 before, and otherwise).
    LaneMask split_lanes() const { return m_split_lanes; }
    /// Ray i's walker (i in split_lanes()).
    virtual Stepper& lane_walker(uint32_t i) = 0;
    /// A packet of one ray.
    void begin(const Ray& ray, TraversalMode mode) override { begin_packet(&ray, &mode, 1); }

    uint32_t size() const { return m_lanes.n; }
    const Ray& lane_ray(uint32_t i) const { return m_lanes.ray[i]; }
    TraversalMode lane_mode(uint32_t i) const { return m_lanes.mode[i]; }
    const Hit& lane_hit(uint32_t i) const { return m_lanes.hit[i]; }
    const WorkCounts& lane_work(uint32_t i) const { return m_lanes.work[i]; }
    /// Rays taking part in the planned step (0 once done).
    uint32_t active() const { return m_plan.done ? 0 : lane_count(m_active); }
    const PacketCounts& counts() const { return m_counts; }

protected:
    /// What every begin_packet() starts with: the rays' lanes, the counts and the Stepper's
    /// state; the live rays are the first step's.
    void start_packet(const Ray* rays, const TraversalMode* modes, uint32_t n) {
        m_lanes.begin(rays, modes, n);
        m_counts = PacketCounts{};
        m_ray = rays[0];
        m_mode = modes[0];
        m_hit = Hit{};
        m_work = WorkCounts{};
        m_stack_size = 0;
        m_split_lanes = 0;
        m_active = m_lanes.live;
    }
    /// Ends the walk: rays without a hit report Hit{}; the Stepper's hit and work are ray 0's.
    void end_packet() {
        m_lanes.finish();
        m_active = 0;
        m_stack_size = 0;
        m_hit = m_lanes.hit[0];
        m_work = m_lanes.work[0];
        m_plan.finish();
    }

    PacketLanes m_lanes;
    LaneMask m_active = 0;  ///< the rays of the planned step
    PacketCounts m_counts;
    float m_split_below = 0.0f;
    SplitWalks m_split_walks = SplitWalks::serial;
    LaneMask m_split_lanes = 0;
};

}  // namespace rtsim
