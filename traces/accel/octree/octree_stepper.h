#pragma once
// The octree's stepper: parametric traversal after Revelles, Urena & Lastra 2000, "An efficient
// parametric algorithm for octree traversal" (WSCG). A cell is known by its six plane distances
// along the ray (the paper's tx0, ty0, tz0, tx1, ty1, tz1); a node step computes the distances to
// its three centre planes (txm, tym, tzm: 3 ray/plane tests on the `plane` pipeline), and every
// child's six distances are then a choice between the parent's and the centre's, with no box test.
// Revelles picks the first child and each next one by a state table over those parameters; here
// the children the ray enters are those whose parameter interval is not empty by the robust box
// test's rule (traces/isect/slab_interval.h: the same folds on the same distances, so exactly the
// cells box_kernel accepts, also at a corner where crossings coincide within rounding), taken in
// order of entry distance, ties broken by (child XOR the ray's octant), the paper's mirroring
// (a ray runs from child 0 towards child 7 of the mirrored cell, so that order is its sequence).
// In exact arithmetic that is Revelles' sequence. Steps:
//
//   clip       no fetch; 1 box test: the ray against the root cell
//   node       fetches the 16-byte OctNode (locality key: the node); an interior node runs 3
//              plane tests, goes on to its nearest child entered and pushes the others (farthest
//              first, so they pop nearest first); a leaf goes on to its list
//   refs, triangles   as the kd-tree's (ref_list.h, with the mailbox)
//
// Pending cells entered beyond the best hit's cull distance are dropped without a fetch.
#include <cstdint>

#include "traces/accel/cell_stepper.h"
#include "traces/accel/listed_regions.h"
#include "traces/accel/octree/octree_layout.h"
#include "traces/common/aabb.h"

namespace rtsim {

/// Where an octree's data lives: arrays and their addresses in the memory image.
using OctView = ListedTreeView<OctNode>;

class OctreeStepper final : public ListCellStepper {
public:
    OctreeStepper(const OctView& view, uint32_t mailbox_entries) : ListCellStepper(mailbox_entries), m_view(view) {}

    void begin(const Ray& ray, TraversalMode mode) override;
    StepOutcome execute() override;

private:
    enum class Phase : uint8_t { clip, node, list };
    /// A cell along the ray: its node, entry distance and six plane distances.
    struct Cell {
        uint32_t node;
        float tn;
        float tlo[3], thi[3];
    };
    void clip();
    void visit(const Cell& cell);
    void interior(const OctNode& node);
    void pop_next();

    OctView m_view;
    bool m_negative[3] = {false, false, false};
    uint32_t m_octant = 0;  ///< bit a: the ray runs down axis a
    Phase m_phase = Phase::clip;
    Cell m_cell{};
    Cell m_stack[kOctMaxStack];
};

}  // namespace rtsim
