#pragma once
// The kd-tree's stepper (docs/accel.md, "kdtree"). Steps:
//
//   clip       no fetch; 1 box test: the ray against the root cell (its interval [tnear, tfar])
//   node       fetches the 8-byte KdNode (locality key: the node); an interior node runs 1 plane
//              test (the split plane's distance) and goes on to the near child, pushing the far
//              one with its interval when the ray enters both; a leaf goes on to its list
//   refs       fetches the leaf's prim_refs list (one contiguous read); no operation
//   triangles  gathers up to 8 listed triangles, one triangle test each (ref_list.h)
//
// Front to back: a child's interval is its parent's cut at the split plane, computed as the
// robust box test computes the child cell's box (traces/isect/slab_interval.h), so the cells
// visited are exactly those the box test accepts. After a leaf the next entry is popped; an entry
// entered beyond the best hit's cull distance is dropped without a fetch, and since pending cells
// lie behind the current one, a hit inside the current leaf ends the ray ("stop at the first hit
// in the current leaf"), while a hit that lies beyond the leaf (its triangle extends into later
// cells) or on its far boundary lets the cells up to it be visited, so the closest hit by
// (t, prim) is the binary BVH's bit for bit. Any hit stops at the first accepted hit.
// With a short stack, restarts follow kd-restart with push-down (cell_stepper.h): each revisit
// is a node step of the same shape (fetch, one plane test), counted in the restart fields.
#include <cstdint>

#include "traces/accel/cell_stepper.h"
#include "traces/accel/kdtree/kd_layout.h"
#include "traces/accel/listed_regions.h"
#include "traces/common/aabb.h"

namespace rtsim {

/// Where a kd-tree's data lives: arrays and their addresses in the memory image.
using KdView = ListedTreeView<KdNode>;

class KdStepper final : public BinaryCellStepper<KdStepper, kKdMaxDepth, ListCellStepper> {
public:
    static constexpr const char* kName = "kd-tree";
    static constexpr uint32_t kNodeTests = 1;  ///< an interior node's plane test
    static constexpr bool kPushDown = true;    ///< kd-restart with push-down (cell_stepper.h)

    KdStepper(const KdView& view, uint32_t mailbox_entries, uint32_t short_stack_entries = 0)
        : BinaryCellStepper(mailbox_entries), m_view(view) {
        configure_short_stack(short_stack_entries);
    }

    void begin(const Ray& ray, TraversalMode mode) override;
    StepOutcome execute() override;

private:
    friend class BinaryCellStepper<KdStepper, kKdMaxDepth, ListCellStepper>;
    enum class Phase : uint8_t { clip, node, list };
    void visit(uint32_t node, const detail::SlabInterval& cell);
    void plan_node(uint32_t node);
    void interior(const KdNode& node);

    KdView m_view;
    Phase m_phase = Phase::clip;
    uint32_t m_node = 0;
    detail::SlabInterval m_cell;
};

}  // namespace rtsim
