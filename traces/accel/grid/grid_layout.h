#pragma once
// The uniform grid's hardware layout (docs/accel.md, "grid"), documented byte by byte:
//
//   region "cells"      GridCell, 8 bytes, x fastest: cell (x, y, z) at x + nx * (y + ny * z)
//   region "prim_refs"  uint32_t, 4 bytes (kRefBytes, ref_list.h): an index into "triangles"; each cell's list is
//                       contiguous, in increasing triangle order
//   region "triangles"  HwTriangle, 48 bytes, each scene triangle once, in scene order (prim = index)
//
// The geometry (resolution, origin, cell size) is the image's params: what a grid unit holds in
// registers. Cell boundaries are the float planes origin + k * cell_size, computed by
// GridGeometry::plane() and nowhere else, so the builder and the traversal agree on every bit.
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "traces/common/aabb.h"
#include "traces/common/record_layout.h"

namespace rtsim {

struct GridCell {          // 8 bytes
    uint32_t first_ref;    // 0: first entry of the cell's list in prim_refs
    uint32_t ref_count;    // 4: entries in the list (0: an empty cell)
};
static_assert(sizeof(GridCell) == 8, "GridCell must be 8 bytes");
inline RecordLayout layout_of(const GridCell*) {
    return {RTSIM_FIELD(GridCell, first_ref), RTSIM_FIELD(GridCell, ref_count)};
}

struct GridGeometry {
    uint32_t res[3] = {1, 1, 1};       ///< cells per axis
    float origin[3] = {0, 0, 0};       ///< the grid's low corner (plane 0 of each axis)
    float cell[3] = {1, 1, 1};         ///< cell size per axis (> 0)

    /// Plane k of `axis` (k in 0..res): the one definition of a cell boundary.
    float plane(int axis, uint32_t k) const { return origin[axis] + float(k) * cell[axis]; }
    uint64_t cell_count() const { return uint64_t(res[0]) * res[1] * res[2]; }
    uint32_t cell_index(uint32_t x, uint32_t y, uint32_t z) const { return x + res[0] * (y + res[1] * z); }
    /// [plane 0, plane res] on every axis: the box the ray is clipped against.
    Aabb bounds() const;
    /// Slabs of `axis` whose closed range [plane k, plane k+1] meets [lo, hi]; false if none.
    bool slab_range(int axis, float lo, float hi, uint32_t* first, uint32_t* last) const;

    nlohmann::json to_json() const;
    /// Reads and checks params (resolution, origin, cell_size); throws rtsim::Error naming
    /// `source` and the field: missing, not finite, a cell size <= 0, planes not increasing.
    static GridGeometry from_json(const nlohmann::json& params, const std::string& source);
};

/// How the grid builder picks its resolution.
struct GridConfig {
    /// Cells per triangle, lambda: the grid has about lambda x N cells, cubic where the scene
    /// is (per unit length cbrt(lambda N / V); Cleary & Wyvill 1988, Wald et al. 2006). More cells
    /// mean fewer triangle tests per cell step but more steps, more references (a triangle is in
    /// every cell its box overlaps) and 8 bytes more per cell.
    float density = 4.0f;
    /// Largest resolution along one axis (bounds the steps across the grid).
    uint32_t max_resolution = 1024;
    /// Most cells in all (the cell region is 8 bytes per cell); lambda N is scaled down to fit.
    uint64_t max_cells = 1ull << 25;

    /// The settings as data (traces/accel/build_settings.h).
    template <class V>
    void visit(V& v) {
        v.field("density", density, "cells/triangle", "lambda: about lambda x N cells, cubic where the scene is", 1e-6, 1e6);
        v.field("max_resolution", max_resolution, "cells", "Largest resolution along one axis", 1, 65536);
        v.field("max_cells", max_cells, "cells", "Most cells in all (8 bytes each); lambda N is scaled down to fit", 1, 4294967296.0);
    }
};

}  // namespace rtsim
