// The two-level packet stepper (two_level_packet.h): the TLAS walk is the binary BVH's packet
// kernel (bvh2_packet_kernel.h), the BLAS walks are their kinds' own packet steppers.
#include "traces/accel/two_level/two_level_packet.h"

#include "traces/accel/two_level/two_level.h"
#include "traces/common/error.h"

namespace rtsim {

namespace {

/// A mask whose count is n (what active() reports while a BLAS packet of n rays steps).
LaneMask low_lanes(uint32_t n) { return n >= kMaxPacketLanes ? ~LaneMask(0) : (LaneMask(1) << n) - 1; }

}  // namespace

TwoLevelPacketStepper::TwoLevelPacketStepper(const TwoLevelAccel& accel, const StepOptions& options)
    : m_accel(accel) {
    set_anyhit_order(options.anyhit_order);  // the TLAS's packet steps; each BLAS packet its own
    for (const auto& blas : accel.blases()) {
        m_blas_packets.push_back(blas->make_packet_stepper(options));
        require(m_blas_packets.back() != nullptr, "two-level packets need a BLAS kind with a packet kernel");
    }
}

Stepper& TwoLevelPacketStepper::lane_walker(uint32_t) {
    throw Error("two-level packets split serially inside instances: no lane walkers");
}

void TwoLevelPacketStepper::begin_packet(const Ray* rays, const TraversalMode* modes, uint32_t n) {
    start_packet(rays, modes, n);
    m_tlas_size = 0;
    m_inner = nullptr;
    m_tlas_active = m_lanes.live;
    if (m_tlas_active == 0 || m_accel.tlas().node_count == 0) return finish();
    m_ref = 0;  // the TLAS root: every valid ray starts there
    m_count = 0;
    plan_tlas();
}

void TwoLevelPacketStepper::plan_tlas() {
    const uint32_t rays = lane_count(m_tlas_active);
    m_active = m_tlas_active;
    m_counts.active_rays += rays;
    if (m_count == 0) {
        ++m_counts.node_steps;
        m_plan.reset(m_accel.tlas_key_base() + m_ref);
        m_plan.add_fetch(m_accel.tlas().node_base + uint64_t(m_ref) * sizeof(HwNode), sizeof(HwNode), DataKind::node);
        m_plan.add_op(OpKind::box, 2 * rays);
    } else {
        ++m_counts.leaf_steps;
        m_plan.reset(kNoLocality);  // an instance record belongs to its TLAS node's treelet
        m_plan.add_fetch(m_accel.instances().base + uint64_t(m_ref) * sizeof(InstanceRecord), kInstanceFetchBytes,
                         DataKind::instance);
        m_plan.add_op(OpKind::transform, rays);
    }
    m_stack_size = m_tlas_size;
}

void TwoLevelPacketStepper::plan_blas() {
    m_plan = m_inner->plan();
    if (m_plan.locality != kNoLocality) m_plan.locality += m_inner_offset;
    m_active = low_lanes(m_inner->active());
    m_stack_size = m_tlas_size + m_inner->stack_size();
}

StepOutcome TwoLevelPacketStepper::execute() {
    if (m_plan.done) return StepOutcome{};
    if (m_inner) {
        const StepOutcome out = m_inner->execute();
        if (m_inner->done()) leave_instance();
        else plan_blas();
        return out;
    }
    if (m_count != 0) {
        enter_instance(m_accel.instances().records[m_ref]);
        return StepOutcome{};
    }
    const LaneMask stepping = m_tlas_active;
    for_each_lane(stepping, [&](uint32_t r) {
        m_lanes.work[r].tlas_steps += 1;  // the TLAS's share (packet_descend counts steps and box tests)
        m_lanes.work[r].tlas_box_tests += 2;
    });
    if (detail::packet_descend(m_lanes, stepping, m_accel.tlas(), m_ref, m_stack, m_tlas_size, &m_ref, &m_count,
                               &m_tlas_active))
        plan_tlas();
    else
        pop_next();
    return StepOutcome{};
}

void TwoLevelPacketStepper::enter_instance(const InstanceRecord& record) {
    // Each ray that entered the instance's box, into its object space, as a packet of its own.
    Ray object[kMaxPacketLanes];
    TraversalMode modes[kMaxPacketLanes];
    uint32_t n = 0;
    for_each_lane(m_tlas_active & m_lanes.live, [&](uint32_t r) {
        m_lanes.work[r].transforms += 1;
        object[n] = transform_ray(record.world_to_object, m_lanes.ray[r]);
        object[n].tmax = m_lanes.hit[r].t;  // t is the same in both spaces: nothing beyond the best hit
        modes[n] = m_lanes.mode[r];
        m_lane_of[n++] = r;
    });
    if (n == 0) return pop_next();
    m_instance = &record;
    m_inner_offset = m_accel.locality_offset(record.blas);
    m_inner = m_blas_packets[record.blas].get();
    // The hybrid inside the instance: the BLAS packet splits below the fraction of its own rays,
    // its rays finishing the instance one after another on this packet's context.
    m_inner->set_split_below(m_split_below);
    m_inner->set_split_walks(SplitWalks::serial);
    m_inner->begin_packet(object, modes, n);
    if (m_inner->done()) leave_instance();
    else plan_blas();
}

void TwoLevelPacketStepper::leave_instance() {
    m_counts += m_inner->counts();
    for (uint32_t j = 0; j < m_inner->size(); ++j) {
        const uint32_t r = m_lane_of[j];
        m_lanes.work[r] += m_inner->lane_work(j);
        const Hit& h = m_inner->lane_hit(j);
        if (!h.valid()) continue;
        // Merge with global primitive ids, so ties between instances break as in a flat scene.
        const uint32_t prim = m_instance->prim_base + uint32_t(h.prim);
        Hit& best = m_lanes.hit[r];
        if (m_lanes.mode[r] == TraversalMode::any_hit || detail::closer(h.t, prim, best.t, best.prim)) {
            best = Hit{int32_t(prim), int32_t(m_instance->instance), h.t, h.u, h.v};
            m_lanes.cull[r] = detail::cull_distance(h.t);
            if (m_lanes.mode[r] == TraversalMode::any_hit) m_lanes.live &= ~lane_bit(r);
        }
    }
    m_inner = nullptr;
    pop_next();
}

void TwoLevelPacketStepper::pop_next() {
    if (m_lanes.live && detail::packet_pop(m_lanes, m_stack, m_tlas_size, &m_ref, &m_count, &m_tlas_active)) {
        plan_tlas();
        return;
    }
    finish();
}

void TwoLevelPacketStepper::finish() {
    m_tlas_active = 0;
    m_tlas_size = 0;
    end_packet();
}

}  // namespace rtsim
