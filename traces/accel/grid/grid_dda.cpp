// The grid's conservative 3D-DDA (grid_dda.h).
#include "traces/accel/grid/grid_dda.h"

#include <cmath>

#include "traces/isect/ray_box_kernel.h"

namespace rtsim {
namespace {

/// The box test's widened far distance (ray_box_kernel.h): moved away from zero by 2 gamma(3).
inline float widen(float far) { return far * (far >= 0.0f ? detail::kFarUp : detail::kFarDown); }

/// First j in [0, n) with pred(j) true for a predicate false then true (n if none).
template <class Pred>
uint32_t first_true(uint32_t n, Pred pred) {
    uint32_t lo = 0, hi = n;
    while (lo < hi) {
        const uint32_t mid = lo + (hi - lo) / 2;
        if (pred(mid)) hi = mid;
        else lo = mid + 1;
    }
    return lo;
}

}  // namespace

float GridDda::Axis::near(uint32_t j) const {
    // Plane j in step order, then the box test's slab distance (plane - origin) * (1 / d).
    const float plane = origin + float(negative ? res - j : j) * cell;
    return (plane - o) * inv;
}

void GridDda::begin(const GridGeometry& grid, const RayBoxPre& pre, float t0) {
    m_grid = grid;
    m_pending = false;
    m_done = false;
    m_event_t = t0;
    for (int a = 0; a < 3; ++a) {
        Axis& ax = m_axis[a];
        ax.res = grid.res[a];
        ax.origin = grid.origin[a];
        ax.cell = grid.cell[a];
        ax.o = pre.origin4[a];
        ax.inv = pre.inv_dir4[a];
        ax.parallel = std::isinf(ax.inv);
        ax.negative = std::signbit(ax.inv);
        if (ax.parallel) {
            // Slabs whose closed range holds the origin, for every t.
            if (!grid.slab_range(a, ax.o, ax.o, &ax.lo, &ax.hi)) m_done = true;
            continue;
        }
        // Slabs active at t0: started (near <= t0) and not ended (widened far >= t0). Both
        // distances rise with j, so the active ones are a range; the grid test guarantees one.
        ax.hi = first_true(ax.res, [&](uint32_t j) { return !(ax.near(j) <= t0); }) - 1;
        ax.lo = first_true(ax.res, [&](uint32_t j) { return widen(ax.far(j)) >= t0; });
        if (ax.hi + 1 == 0 || ax.lo > ax.hi) m_done = true;  // (never after a grid-bounds hit)
    }
    if (m_done) return;
    for (int a = 0; a < 3; ++a) m_from[a] = m_cur[a] = m_axis[a].lo, m_to[a] = m_axis[a].hi;
    m_pending = true;
}

bool GridDda::event() {
    // The next slab to start, over the axes that have one; ties to the lower axis.
    int a = -1;
    float s = 0.0f;
    for (int b = 0; b < 3; ++b) {
        if (!m_axis[b].more()) continue;
        const float t = m_axis[b].near(m_axis[b].hi + 1);
        if (a < 0 || t < s) a = b, s = t;
    }
    if (a < 0) return false;
    // Slabs whose widened interval ended before s share no point with the new slab.
    for (Axis& ax : m_axis) {
        if (ax.parallel) continue;
        while (ax.lo <= ax.hi && widen(ax.far(ax.lo)) < s) ++ax.lo;
        if (ax.lo > ax.hi && !ax.more()) return false;  // this axis has left the grid
    }
    Axis& ax = m_axis[a];
    ++ax.hi;
    m_event_t = s;
    // The new cells: the new slab of axis a with every active slab of the others.
    for (int b = 0; b < 3; ++b) m_from[b] = m_cur[b] = m_axis[b].lo, m_to[b] = m_axis[b].hi;
    m_from[a] = m_cur[a] = m_to[a] = ax.hi;
    m_pending = true;
    for (int b = 0; b < 3; ++b) m_pending = m_pending && m_from[b] <= m_to[b];
    return true;
}

bool GridDda::next(float cull, uint32_t* cell) {
    while (!m_done) {
        if (m_pending) {
            // Entry distances never fall: once one exceeds the cull distance, nothing follows.
            if (!(m_event_t <= cull)) break;
            *cell = m_grid.cell_index(m_axis[0].slab(m_cur[0]), m_axis[1].slab(m_cur[1]), m_axis[2].slab(m_cur[2]));
            // Odometer over the event's box of step coordinates, x fastest.
            m_pending = false;
            for (int b = 0; b < 3 && !m_pending; ++b) {
                if (m_cur[b] < m_to[b]) {
                    ++m_cur[b];
                    m_pending = true;
                } else {
                    m_cur[b] = m_from[b];
                }
            }
            return true;
        }
        if (!event() || !(m_event_t <= cull)) break;
    }
    m_done = true;
    return false;
}

}  // namespace rtsim
