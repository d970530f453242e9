#pragma once
// The uniform grid behind the acceleration-structure seam (docs/accel.md, "grid"): regions
// "cells" (GridCell), "prim_refs" (uint32 triangle indices) and "triangles" (HwTriangle), the
// geometry in the image's params (grid_layout.h). Built by binning every triangle into every
// cell its box overlaps; traversed by a conservative 3D-DDA (grid_dda.h) with no stack.
#include <memory>
#include <string>

#include "traces/accel/accel.h"
#include "traces/accel/grid/grid_layout.h"
#include "traces/accel/grid/grid_stepper.h"

namespace rtsim {

struct Scene;

/// The image of a uniform grid over a flattened scene (which may have no triangles: then one
/// empty cell). Deterministic. Throws rtsim::Error on a non-finite vertex or a bad config.
AccelImage grid_image(const Scene& scene, const GridConfig& config = {});

/// Throws rtsim::Error naming `source` and the record if the view is not a grid the stepper can
/// walk: cell count not the resolution's, a cell's list outside prim_refs, a reference outside
/// triangles. Linear time.
void validate_grid(const GridView& view, const std::string& source);

/// Throws rtsim::Error naming the first broken layout invariant of a built grid: a triangle
/// record that is not the scene's, a triangle missing from a cell its box overlaps or listed in
/// one it does not overlap, a list not in increasing order, counts that do not add up.
void check_grid_invariants(const GridView& view, const Scene& scene);

/// Bricks of b x b x b cells, b the largest power of two whose every brick fits the budget
/// (a brick brings its cells, their lists and one triangle per reference); a single cell over
/// the budget is a brick alone. Keys are cell indices; every cell is in exactly one brick.
LocalityPartition grid_partition(const GridView& view, uint64_t budget_bytes);

class GridAccel final : public Accel {
public:
    GridAccel(AccelImage image, const std::string& source);

    std::unique_ptr<Stepper> make_stepper(const StepOptions& options = {}) const override;
    /// Packets whose rays each run their own DDA, visiting cells in lock step (grid_packet.h).
    std::unique_ptr<PacketStepper> make_packet_stepper(const StepOptions& options = {}) const override;
    /// The stepper's own loop on a stack instance (no allocation, no virtual calls).
    Hit trace(const Ray& ray, TraversalMode mode, WorkCounts* work = nullptr,
              const StepOptions& options = {}) const override;
    LocalityPartition partition(uint64_t budget_bytes) const override;
    std::vector<OpKind> op_kinds() const override;
    uint32_t max_stack_entries() const override { return 0; }  // no stack
    const GridView& view() const { return m_view; }

private:
    GridView m_view;
};

}  // namespace rtsim
