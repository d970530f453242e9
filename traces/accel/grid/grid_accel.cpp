// The uniform grid's Accel: validation when loaded, steppers, the reference loop (grid.h).
#include <string>

#include "traces/accel/grid/grid.h"
#include "traces/accel/grid/grid_packet.h"
#include "traces/accel/listed_regions.h"
#include "traces/common/error.h"

namespace rtsim {

void validate_grid(const GridView& v, const std::string& source) {
    const ListedChecks check(source, "grid");
    const GridGeometry& g = v.geometry;
    if (v.cell_count != g.cell_count())
        check.fail("resolution " + std::to_string(g.res[0]) + " x " + std::to_string(g.res[1]) + " x " +
             std::to_string(g.res[2]) + " needs " + std::to_string(g.cell_count()) + " cells, region 'cells' holds " +
             std::to_string(v.cell_count));
    if (v.ref_count >= (1ull << 32) || v.triangle_count >= (1ull << 32)) check.fail("more than 2^32 references or triangles");
    // Lists back to back in record order, each reference in one list: the listed references
    // total prim_refs' count, so a ray's work is bounded by the image (overlapping lists, every
    // cell listing every reference, would cost cells x references per ray).
    uint64_t next = 0;
    for (uint64_t c = 0; c < v.cell_count; ++c) {
        const GridCell& cell = v.cells[c];
        check.list_in_range("cell", c, cell.first_ref, cell.ref_count, v.ref_count);
        if (cell.first_ref != next)
            check.fail("cell " + std::to_string(c) + "'s list starts at prim_refs " + std::to_string(cell.first_ref) +
                 ", not " + std::to_string(next) + " where the previous cell's ends (lists must be back to back "
                 "in cell order, each reference in one list)");
        next += cell.ref_count;
    }
    if (next != v.ref_count)
        check.fail("the cells list " + std::to_string(next) + " of prim_refs' " + std::to_string(v.ref_count) + " references");
    check.refs_name_triangles(v.list, v.ref_count, v.triangle_count);
}

GridAccel::GridAccel(AccelImage image, const std::string& source) : Accel(std::move(image)) {
    // Regions, then params, then the triangles (decoded when compressed): the order errors come in.
    check_listed_regions(m_image, "grid", "cells", DataKind::cell, uint32_t(sizeof(GridCell)), source);
    m_view.geometry = GridGeometry::from_json(m_image.params, source);
    const ListedRegions r = open_listed_regions(m_image, m_triangles, "grid", "cells", DataKind::cell,
                                                uint32_t(sizeof(GridCell)), source);
    m_view.cells = r.cells->records<GridCell>();
    m_view.list = r.list;
    m_view.cell_count = r.cells->count;
    m_view.ref_count = r.ref_count;
    m_view.triangle_count = r.triangle_count;
    m_view.cell_base = r.cells->base;
    validate_grid(m_view, source);
}

std::unique_ptr<Stepper> GridAccel::make_stepper(const StepOptions& options) const {
    return std::make_unique<GridStepper>(m_view, options.mailbox_entries);
}

std::unique_ptr<PacketStepper> GridAccel::make_packet_stepper(const StepOptions& options) const {
    return std::make_unique<GridPacketStepper>(m_view, options.mailbox_entries);
}

Hit GridAccel::trace(const Ray& ray, TraversalMode mode, WorkCounts* work, const StepOptions& options) const {
    GridStepper stepper(m_view, options.mailbox_entries);
    return trace_with_stepper(stepper, ray, mode, work);
}

LocalityPartition GridAccel::partition(uint64_t budget_bytes) const { return grid_partition(m_view, budget_bytes); }

std::vector<OpKind> GridAccel::op_kinds() const {
    return with_record_kinds({OpKind::box, OpKind::cell, OpKind::triangle});
}

}  // namespace rtsim
