#include "rtl_model/dispatch/ray_sort.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace rtsim {

namespace {

/// `bits` bits of x in [lo, hi] (0 when the range is empty or x is not finite).
uint32_t quantise(float x, float lo, float hi, uint32_t bits) {
    const float span = hi - lo;
    if (!(span > 0.0f) || !(x >= lo)) return 0;
    const float f = std::min((x - lo) / span, 1.0f) * float((1u << bits) - 1);
    return uint32_t(f + 0.5f);
}

/// Interleaves the low `bits` bits of `values` (n of them), most significant bit first.
uint32_t interleave(const uint32_t* values, int n, uint32_t bits) {
    uint32_t key = 0;
    for (int b = int(bits) - 1; b >= 0; --b)
        for (int i = 0; i < n; ++i) key = (key << 1) | ((values[i] >> b) & 1u);
    return key;
}

}  // namespace

uint32_t ray_sort_key(const Ray& ray, RaySort sort, const Vec3& lo, const Vec3& hi) {
    const Vec3& o = ray.origin;
    const Vec3& d = ray.direction;
    switch (sort) {
        case RaySort::none: return 0;
        case RaySort::octant: return (d.x < 0.0f ? 4u : 0u) | (d.y < 0.0f ? 2u : 0u) | (d.z < 0.0f ? 1u : 0u);
        case RaySort::morton: {
            const uint32_t q[3] = {quantise(o.x, lo.x, hi.x, 10), quantise(o.y, lo.y, hi.y, 10), quantise(o.z, lo.z, hi.z, 10)};
            return interleave(q, 3, 10);
        }
        case RaySort::origin_direction: {
            const float len = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
            const float inv = len > 0.0f ? 1.0f / len : 0.0f;
            const uint32_t q[6] = {quantise(o.x, lo.x, hi.x, 5),        quantise(o.y, lo.y, hi.y, 5),
                                   quantise(o.z, lo.z, hi.z, 5),        quantise(d.x * inv, -1.0f, 1.0f, 5),
                                   quantise(d.y * inv, -1.0f, 1.0f, 5), quantise(d.z * inv, -1.0f, 1.0f, 5)};
            return interleave(q, 6, 5);
        }
    }
    return 0;
}

void RaySorter::sort(std::vector<RayJob>& rays) {
    const size_t window = m_config.sort_window;
    std::vector<uint32_t> keys;
    std::vector<size_t> order;
    std::vector<RayJob> sorted;
    for (size_t first = 0; first < rays.size(); first += window) {
        const size_t n = std::min(window, rays.size() - first);
        // The window's origin bounds (finite origins only): the Morton grid of its keys.
        Vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
        for (size_t i = first; i < first + n; ++i)
            if (std::isfinite(rays[i].ray.origin.x) && std::isfinite(rays[i].ray.origin.y) && std::isfinite(rays[i].ray.origin.z)) {
                lo = glm::min(lo, rays[i].ray.origin);
                hi = glm::max(hi, rays[i].ray.origin);
            }
        keys.resize(n);
        for (size_t i = 0; i < n; ++i) keys[i] = ray_sort_key(rays[first + i].ray, m_config.sort, lo, hi);
        order.resize(n);
        std::iota(order.begin(), order.end(), size_t(0));
        std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return keys[a] < keys[b]; });
        sorted.clear();
        for (size_t i : order) sorted.push_back(rays[first + i]);
        // The stage's time: sorted at its throughput, ready `sort_latency` after its last ray.
        m_sorted += n;
        const Cycle done = (m_sorted + m_config.sort_rays_per_cycle - 1) / m_config.sort_rays_per_cycle;
        m_ready = std::max(m_ready, done + m_config.sort_latency);
        for (size_t i = 0; i < n; ++i) {
            rays[first + i] = sorted[i];
            rays[first + i].not_before = std::max(rays[first + i].not_before, m_ready);
        }
    }
}

}  // namespace rtsim
