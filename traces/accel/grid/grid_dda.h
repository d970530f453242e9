#pragma once
// The grid's cell order: a 3D-DDA (Amanatides & Woo 1987, "A fast voxel traversal algorithm for
// ray tracing") made conservative so a uniform grid misses nothing the binary BVH finds.
//
// Per axis the ray is in slab k over the t-interval [near, far] between the crossings of the
// slab's two planes, computed exactly as the robust box test computes slab distances (Ize 2013;
// traces/isect/ray_box_kernel.h), with far widened by the same 1 + 2 gamma(3). A cell is
// visited iff its three widened intervals and [tmin, cull] share a point: exactly the cells the
// ray/box test would accept, so rounding can never skip a cell the ray truly crosses (at a
// corner where crossings on two axes are within rounding, both orders' cells are visited).
// A classic DDA steps to one next cell; this one sweeps the crossings in order of t and emits
// each cell once, when its last slab starts, in non-decreasing order of entry distance.
// A ray parallel to an axis (direction +-0) stays in the slabs whose closed range holds its
// origin (two when it lies on a plane), as the box test counts a ray in a face plane as inside.
#include <cstdint>

#include "traces/accel/grid/grid_layout.h"
#include "traces/isect/ray_box.h"

namespace rtsim {

class GridDda {
public:
    /// Starts at t0, the entry distance of the grid-bounds test (which must have hit).
    void begin(const GridGeometry& grid, const RayBoxPre& pre, float t0);
    /// The next cell (linear index) whose entry distance is <= cull; false when none is left.
    /// Cells come in non-decreasing entry order, so a false is final.
    bool next(float cull, uint32_t* cell);
    /// Entry distance of the cell next() returned last.
    float entry() const { return m_event_t; }

private:
    struct Axis {
        bool parallel = false;
        bool negative = false;  ///< direction < 0: step coordinates run from the last slab down
        uint32_t res = 1;
        float origin = 0, cell = 1, o = 0, inv = 1;
        uint32_t lo = 0, hi = 0;  ///< active slabs [lo, hi] in step coordinates (lo > hi: none)

        /// Crossing distance of plane j in step coordinates (the near plane of step slab j).
        float near(uint32_t j) const;
        float far(uint32_t j) const { return near(j + 1); }
        uint32_t slab(uint32_t j) const { return parallel || !negative ? j : res - 1 - j; }
        bool more() const { return !parallel && hi + 1 < res; }
    };
    bool event();  ///< processes the next slab start; false when no cell can follow

    GridGeometry m_grid;
    Axis m_axis[3];
    bool m_pending = false;  ///< cells of the current event remain
    bool m_done = false;
    float m_event_t = 0;     ///< entry distance of the current event's cells
    uint32_t m_from[3], m_to[3], m_cur[3];  ///< the current event's cells: a box of step coordinates
};

}  // namespace rtsim
