#include "traces/accel/packet_stepper.h"

#include <string>

#include "traces/common/error.h"
#include "traces/isect/leaf_kernel.h"

namespace rtsim {

void PacketLanes::begin(const Ray* rays, const TraversalMode* modes, uint32_t count) {
    require(count >= 1 && count <= kMaxPacketLanes,
            "packet of " + std::to_string(count) + " rays: a packet holds 1 to " + std::to_string(kMaxPacketLanes));
    n = count;
    live = 0;
    for (uint32_t i = 0; i < n; ++i) {
        ray[i] = rays[i];
        mode[i] = modes[i];
        hit[i] = Hit{};
        work[i] = WorkCounts{};
        if (!ray_is_valid(rays[i])) continue;
        box[i] = ray_box_precompute(rays[i]);
        tri[i] = ray_triangle_precompute(rays[i]);
        hit[i].t = rays[i].tmax;
        cull[i] = detail::cull_distance(rays[i].tmax);
        live |= lane_bit(i);
    }
}

void PacketLanes::finish() {
    for (uint32_t i = 0; i < n; ++i)
        if (hit[i].prim < 0) hit[i] = Hit{};
    live = 0;
}

}  // namespace rtsim
