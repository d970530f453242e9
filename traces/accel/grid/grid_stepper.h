#pragma once
// The uniform grid's stepper (docs/accel.md, "grid"). Steps:
//
//   clip       no fetch; 1 box test: the ray against the grid's bounds (the entry distance)
//   cell       fetches the 8-byte GridCell; 1 cell operation (the DDA step to it); locality key:
//              the cell. An empty cell goes on to the next cell.
//   refs       fetches the cell's prim_refs list (one contiguous read); no operation
//   triangles  gathers up to 8 of the listed triangles (one 48-byte fetch each); one triangle
//              test each; a longer list takes several such steps (ref_list.h)
//
// Each triangle is tested against the ray's own [tmin, tmax] and the best hit is the closest
// by (t, prim) (traces/isect/leaf_kernel.h), so a triangle listed in several cells is harmless;
// with a mailbox (mailbox.h) its retests are skipped.
// The DDA hands out cells in order of entry distance and stops at the first whose entry exceeds
// the cull distance of the best hit: every cell that can hold a closer hit has been tested, so
// the first hit found that way is the closest, bit for bit the binary BVH's. Any hit stops at
// the first accepted hit. No stack.
#include <cstdint>

#include "traces/accel/cell_stepper.h"
#include "traces/accel/grid/grid_dda.h"
#include "traces/common/hw_triangle.h"

namespace rtsim {

/// Where a grid's data lives: arrays and their addresses in the memory image.
struct GridView {
    GridGeometry geometry;
    const GridCell* cells = nullptr;
    RefListView list;  ///< the cells' lists and the triangles they index
    uint64_t cell_count = 0, ref_count = 0, triangle_count = 0;
    uint64_t cell_base = 0;  ///< address of cell 0
};

class GridStepper final : public ListCellStepper {
public:
    GridStepper(const GridView& view, uint32_t mailbox_entries) : ListCellStepper(mailbox_entries), m_view(view) {}

    void begin(const Ray& ray, TraversalMode mode) override;
    StepOutcome execute() override;

private:
    enum class Phase : uint8_t { clip, cell, list };
    void clip();
    void next_cell();        ///< the DDA's next cell, or the end

    GridView m_view;
    GridDda m_dda;
    Phase m_phase = Phase::clip;
    uint32_t m_cell = 0;    ///< the current cell
};

}  // namespace rtsim
