#include "rtl_model/traversal/packet/packet_profile.h"

#include <algorithm>

#include "rtl_model/common/interfaces.h"
#include "rtl_model/traversal/packet/packet_config.h"
#include "rtl_model/traversal/traversal_config.h"
#include "traces/accel/accel.h"

namespace rtsim {

namespace {

/// One unit's rays in packets of pc.lanes, in the order dispatch deals them.
GroupProfile packets_of(const Accel& accel, const StepOptions& step, const PacketConfig& pc,
                        const std::vector<RayJob>& rays) {
    GroupProfile p;
    p.rays = double(rays.size());
    std::vector<Ray> group;
    std::vector<TraversalMode> modes;
    std::vector<Hit> hits(pc.lanes);
    std::vector<WorkCounts> work(pc.lanes);
    for (size_t first = 0; first < rays.size(); first += pc.lanes) {
        const size_t n = std::min<size_t>(pc.lanes, rays.size() - first);
        group.clear(), modes.clear();
        for (size_t i = 0; i < n; ++i) {
            group.push_back(rays[first + i].ray);
            modes.push_back(rays[first + i].any_hit ? TraversalMode::any_hit : TraversalMode::closest_hit);
        }
        PacketCounts counts;
        accel.trace_packet(group.data(), modes.data(), uint32_t(n), hits.data(), work.data(), &counts,
                           float(pc.split_below), step.reference_walk());
        const double steps = double(counts.node_steps + counts.leaf_steps);
        p.group_steps += steps;
        p.scheduler_steps += 1 + 2 * steps;  // the packet's ray fetch, then each step and its operations
        p.lane_slots += steps * pc.lanes;
        p.active_lanes += double(counts.active_rays);
        p.requests += steps;  // one fetch serves the packet's active rays
        double tri_tests = 0, sphere_tests = 0, capsule_tests = 0, rotations = 0;
        double node_tests[3] = {0, 0, 0};  // box tests, plane tests, cell steps: what a node step runs
        for (size_t i = 0; i < n; ++i) {
            WorkCounts alone;
            accel.trace(group[i], modes[i], &alone, step);
            for (size_t f = 0; f < p.work.size(); ++f) {
                p.work[f] += work[i].*kWorkFields[f].member;
                p.single_work[f] += alone.*kWorkFields[f].member;
            }
            p.lane_requests += plan_step_work(alone);
            tri_tests += work[i].tri_tests, sphere_tests += work[i].sphere_tests;
            capsule_tests += work[i].capsule_tests;
            node_tests[0] += work[i].box_tests, node_tests[1] += work[i].plane_tests, node_tests[2] += work[i].cell_steps;
            rotations += work[i].obb_rotations;
        }
        // Node steps by the operation kind they run: a BVH's box tests, a kd-tree's or BIH's plane
        // tests, a grid's cell steps (a structure's few others, such as a kd-tree's one clip
        // against the scene box, shared in proportion). Counted all as box steps, a kd-tree
        // packet's steps were priced at the box pipeline's latency (analytic 10-28% slow).
        const double node_all = node_tests[0] + node_tests[1] + node_tests[2];
        const OpKind node_kinds[3] = {OpKind::box, OpKind::plane, OpKind::cell};
        for (int k = 0; k < 3; ++k)
            p.kind_steps[size_t(node_kinds[k])] +=
                node_all > 0 ? double(counts.node_steps) * node_tests[k] / node_all : (k == 0 ? double(counts.node_steps) : 0.0);
        // An oriented node's step rotates its rays first (obvh2: one rotation and two box tests
        // per ray): its share of the box steps also runs the obb pipeline ahead of the boxes.
        if (rotations > 0 && node_tests[0] > 0) {
            const double box_steps = double(counts.node_steps) * node_tests[0] / node_all;
            p.kind_steps[size_t(OpKind::obb)] += box_steps * std::min(1.0, 2.0 * rotations / node_tests[0]);
        }
        // Leaf steps by the kind of their tests: shared out by the packet's triangle, sphere and
        // capsule tests (a leaf of several kinds runs each; counted here as one, in proportion).
        const double tests = tri_tests + sphere_tests + capsule_tests;
        const double leaves = double(counts.leaf_steps);
        p.kind_steps[size_t(OpKind::triangle)] += tests > 0 ? leaves * tri_tests / tests : leaves;
        if (tests > 0) {
            p.kind_steps[size_t(OpKind::sphere)] += leaves * sphere_tests / tests;
            p.kind_steps[size_t(OpKind::capsule)] += leaves * capsule_tests / tests;
        }
    }
    return p;
}

}  // namespace

GroupProfile packet_group_profile(const Accel& accel, const StepOptions& step, const TraversalConfig& traversal,
                                  const std::vector<std::vector<RayJob>>& rays_by_unit, const GroupSetup&) {
    const PacketConfig& pc = traversal.kind_config<PacketConfig>();
    GroupProfile p;
    for (const std::vector<RayJob>& rays : rays_by_unit) p += packets_of(accel, step, pc, rays);
    return p;
}

}  // namespace rtsim
