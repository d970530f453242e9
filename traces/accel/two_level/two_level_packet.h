#pragma once
// Packets through two levels (Wald et al. 2001 packets, on the two-level structure of
// two_level.h): the packet walks the TLAS like the binary BVH's packet (bvh2_packet_kernel.h:
// one node fetch, each active ray's two box tests, the shared stack); at an instance leaf a
// transform step fetches the instance record once and transforms each active ray into the
// instance's object space (one transform operation per ray), and the rays that entered walk the
// BLAS as a packet of their own with the BLAS kind's packet stepper; its steps are this packet's
// until it is done, when each ray's hit is merged (closest by (t, primitive id) with global ids,
// as the single-ray two-level stepper merges it) and the TLAS walk resumes.
//
// Work per ray: the TLAS steps and box tests it took part in (counted in steps, box_tests and
// the TLAS's share, tlas_steps and tlas_box_tests), one transform per instance entered, and its
// BLAS packets' work. Counts: TLAS node steps as node steps, transform steps as leaf steps, the
// BLAS packets' counts added. The hybrid's split (set_split_below; Benthin et al. 2012) acts
// inside instances: a BLAS packet whose active rays at a node are fewer than the fraction of the
// rays that entered the instance splits, and they finish the instance alone, one after another
// on the packet's context (SplitWalks::serial whatever set_split_walks says), each from its own
// part of the BLAS packet's stack with the BLAS kind's single-ray rules; the TLAS walk resumes as
// a packet after it. The TLAS walk itself never splits.
#include <memory>
#include <vector>

#include "traces/accel/bvh2/bvh2_packet_kernel.h"
#include "traces/accel/packet_stepper.h"
#include "traces/accel/step_options.h"
#include "traces/accel/two_level/instance_record.h"

namespace rtsim {

class TwoLevelAccel;

class TwoLevelPacketStepper final : public PacketStepper {
public:
    TwoLevelPacketStepper(const TwoLevelAccel& accel, const StepOptions& options);

    void begin_packet(const Ray* rays, const TraversalMode* modes, uint32_t n) override;
    StepOutcome execute() override;
    /// Never called: a two-level packet's split rays walk serially (split_lanes() stays 0).
    Stepper& lane_walker(uint32_t i) override;

private:
    void plan_tlas();
    void enter_instance(const InstanceRecord& record);
    void plan_blas();
    void leave_instance();
    void pop_next();
    void finish();

    const TwoLevelAccel& m_accel;
    std::vector<std::unique_ptr<PacketStepper>> m_blas_packets;  ///< one per BLAS, reused
    uint32_t m_ref = 0;    ///< TLAS node, or instance record (m_count != 0)
    uint32_t m_count = 0;
    LaneMask m_tlas_active = 0;  ///< the rays of the TLAS step (or of the instance being walked)
    int m_tlas_size = 0;
    detail::PacketStackEntry m_stack[kTraversalStackSize];
    PacketStepper* m_inner = nullptr;  ///< the BLAS packet being walked, or null in the TLAS
    const InstanceRecord* m_instance = nullptr;
    uint32_t m_inner_offset = 0;
    uint32_t m_lane_of[kMaxPacketLanes];  ///< the BLAS packet's ray j is this packet's ray m_lane_of[j]
};

}  // namespace rtsim
