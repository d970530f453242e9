#pragma once
// Packets on the binary BVH (Wald et al. 2001; rules in bvh2_packet_kernel.h): the packet stepper
// the model's packet unit drives, and the fused packet loop the hit checker takes packet work
// from. Both share the kernel, so they agree on every ray's hit and work and on the packet's
// counts (tested, with the hits against single-ray traversal).
//
// A packet step fetches one 64-byte HwNode and runs 2 box tests per active ray (locality key:
// the node), or fetches a leaf's HwTriangles once and runs one triangle test per triangle and
// active ray, plus the alpha tests the hits call for.
#include <cstdint>
#include <memory>
#include <vector>

#include "traces/accel/bvh2/bvh2_packet_kernel.h"
#include "traces/accel/bvh2/bvh2_stepper.h"

namespace rtsim {

namespace detail {
/// The binary BVH's single-ray rules for a ray walking alone on its lane (LaneWalker).
struct Bvh2LaneRules {
    using Entry = Bvh2StackEntry;
    Bvh2View view;
    bool descend(PacketLanes& p, uint32_t r, uint32_t* ref, uint32_t* count, std::vector<Entry>& stack,
                 int& size) const {
        return detail::lane_descend(p, r, view, ref, count, stack.data(), size);
    }
    void plan(StepPlan& plan, uint32_t ref, uint32_t count) const;
    const HwTriangle* leaf(uint32_t ref) const { return view.triangles + ref; }
};
}  // namespace detail

class Bvh2PacketStepper final : public PacketStepper {
public:
    explicit Bvh2PacketStepper(const Bvh2View& view) : m_view(view) {}

    void begin_packet(const Ray* rays, const TraversalMode* modes, uint32_t n) override;
    StepOutcome execute() override;
    Stepper& lane_walker(uint32_t i) override { return m_walkers[i]; }
    /// The packet's shared stack's top entries (none while a split packet's rays walk in turn).
    uint32_t stack_reads(Fetch* out, uint32_t max) const override;

private:
    void pop_next();
    void plan_next();
    void launch_lanes();
    void finish();

    Bvh2View m_view;
    uint32_t m_ref = 0;    ///< node index, or first triangle of a leaf
    uint32_t m_count = 0;  ///< 0: m_ref is a node; else the leaf's triangle count
    bool m_split = false;  ///< the hybrid: the packet split, its rays walk alone (m_walk)
    detail::SplitWalk m_walk;
    detail::PacketStackEntry m_stack[kTraversalStackSize];
    std::vector<LaneWalker<detail::Bvh2LaneRules>> m_walkers;  ///< SplitWalks::lanes: one per lane
};

/// The packet stepper of a binary BVH's view (bvh2, and obvh2's oriented nodes), walking
/// any-hit packets in `anyhit_order`: what Accel::make_packet_stepper returns for both kinds.
std::unique_ptr<PacketStepper> make_bvh2_packet_stepper(const Bvh2View& view, AnyHitOrder anyhit_order);

/// The fused packet loop: rays[0, n) traced as one packet; each ray's hit and work, and the
/// packet's counts (any of hits, work, counts may be null). `split_below`: the hybrid's threshold
/// (PacketStepper::set_split_below; 0: never split); `anyhit_order` as PacketStepper::set_anyhit_order.
void trace_packet_bvh2(const Bvh2View& bvh, const Ray* rays, const TraversalMode* modes, uint32_t n, Hit* hits,
                       WorkCounts* work, PacketCounts* counts, float split_below = 0.0f,
                       AnyHitOrder anyhit_order = AnyHitOrder::nearest);

}  // namespace rtsim
