#pragma once
// Ray sorting at dispatch (dispatch.sort): a modelled sorting stage between the trace and the
// dealer. It takes `sort_window` consecutive rays at a time, computes each ray's key and hands the
// window out in key order (a stable sort: rays with equal keys keep their trace order), so that
// rays dealt to one unit, and the lanes of one SIMT warp, are coherent (Garanzha & Loop 2010;
// Meister et al. 2020 compare such keys). Keys:
//
//   octant            the direction's sign bits (3 bits): rays into the same octant visit
//                     the BVH's children in the same order
//   morton            the origin's Morton code (10 bits per axis) in the window's origin bounds
//   origin_direction  origin and direction interleaved (5 bits per axis each, 30 bits): close
//                     origins with close directions (Meister et al. 2020's origin+direction key)
//
// Its cost: the stage sorts `sort_rays_per_cycle` rays per cycle and a window's first ray
// leaves `sort_latency` cycles after its last ray was sorted; it runs ahead of the units
// (double-buffered), so it costs time only when the units trace faster than it sorts, and at
// the start. A ray may not enter a context before its window is ready (RayJob::not_before).
#include <cstdint>
#include <vector>

#include "rtl_model/common/interfaces.h"
#include "rtl_model/dispatch/dispatch_config.h"

namespace rtsim {

/// The key of `ray` under `sort` (origins quantised in [lo, hi] per axis).
uint32_t ray_sort_key(const Ray& ray, RaySort sort, const Vec3& lo, const Vec3& hi);

/// The sorting stage: sorts each window of the rays it is given and stamps when they are ready.
class RaySorter {
public:
    explicit RaySorter(const DispatchConfig& config) : m_config(config) {}
    /// Sorts `rays` window by window (in place) and sets each ray's not_before.
    void sort(std::vector<RayJob>& rays);
    uint64_t sorted() const { return m_sorted; }
    Cycle ready() const { return m_ready; }

private:
    DispatchConfig m_config;
    uint64_t m_sorted = 0;  ///< rays through the stage so far
    Cycle m_ready = 0;      ///< when the last window was ready
};

}  // namespace rtsim
