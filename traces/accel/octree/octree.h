#pragma once
// The adaptive octree behind the acceleration-structure seam (docs/accel.md, "octree"): a cell
// listing more than max_leaf_size references is cut at its centre into up to 8 children (empty
// ones not stored), down to max_depth; triangles clipped to the child cells; 16-byte nodes
// (octree_layout.h); parametric traversal after Revelles et al. 2000 (octree_stepper.h) with
// three ray/plane tests per interior node on the `plane` pipeline.
#include <memory>
#include <string>
#include <vector>

#include "traces/accel/accel.h"
#include "traces/accel/octree/octree_layout.h"
#include "traces/accel/octree/octree_stepper.h"

namespace rtsim {

struct Scene;

/// The image over a flattened scene's triangles: regions nodes, prim_refs, triangles; params
/// {"bounds": [lo, hi]}. Deterministic. Throws rtsim::Error on a non-finite vertex, an empty scene
/// or a tree that does not fit the layout.
AccelImage octree_image(const Scene& scene, const OctreeConfig& config = {});

/// Throws rtsim::Error naming `source` and the record if the view is not an octree the stepper
/// can walk: children not after their parent or out of range, a node with two parents or none, a
/// centre outside its cell, a list outside prim_refs, a reference outside triangles, a tree deeper
/// than kOctMaxDepth. Linear time. Returns the depth.
uint32_t validate_octree(const OctView& view, const std::string& source);

/// Throws rtsim::Error naming the first broken invariant: triangle records not the scene's, a
/// list not increasing, a triangle with area in a leaf's cell that the leaf does not list.
void check_octree_invariants(const OctView& view, const Scene& scene);

class OctreeAccel final : public Accel {
public:
    OctreeAccel(AccelImage image, const std::string& source);

    std::unique_ptr<Stepper> make_stepper(const StepOptions& options = {}) const override;
    /// Packets of rays sharing one walk (cell_packet.h), each ray with its own mailbox.
    std::unique_ptr<PacketStepper> make_packet_stepper(const StepOptions& options = {}) const override;
    Hit trace(const Ray& ray, TraversalMode mode, WorkCounts* work = nullptr,
              const StepOptions& options = {}) const override;
    LocalityPartition partition(uint64_t budget_bytes) const override;
    std::vector<OpKind> op_kinds() const override;
    uint32_t max_stack_entries() const override { return 7 * m_depth; }
    const OctView& view() const { return m_view; }

private:
    OctView m_view;
    uint32_t m_depth = 0;
};

/// The child cell c of `cell` cut at `centre` (bit a of c: the upper half of axis a).
inline Aabb octree_child_cell(const Aabb& cell, const float centre[3], uint32_t c) {
    Aabb k = cell;
    for (int a = 0; a < 3; ++a) (c >> a & 1u ? k.lo[a] : k.hi[a]) = centre[a];
    return k;
}

}  // namespace rtsim
