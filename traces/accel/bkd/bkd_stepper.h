#pragma once
// The B-Kd tree's stepper (docs/accel.md, "bkd"). Steps:
//
//   clip       no fetch; 1 box test: the ray against the root cell
//   node       fetches the 20-byte BkdNode (locality key: the node); an interior node runs 4 plane
//              tests (its two intervals' distances) and goes on to the near child, pushing the far
//              one with its interval when the ray enters both; a leaf goes on to its triangles
//   leaf       fetches the leaf's triangles (contiguous) and runs one triangle test each
//
// As in the kd-tree (kd_stepper.h), a child's interval is its parent's cut at its two planes,
// exactly the robust box test of the child's cell (traces/isect/slab_interval.h); pending cells
// entered beyond the best hit's cull distance are dropped without a fetch. Children may overlap
// (hi0 > lo1), so a hit in the near child does not end the ray by itself: the cull rule
// decides, and the closest hit by (t, prim) is the binary BVH's bit for bit.
#include <cstdint>

#include "traces/accel/bkd/bkd_layout.h"
#include "traces/accel/cell_stepper.h"
#include "traces/accel/leaf_blocks.h"
#include "traces/common/aabb.h"
#include "traces/common/hw_triangle.h"

namespace rtsim {

/// Where a B-Kd tree's data lives: arrays and their addresses in the memory image.
struct BkdView {
    const BkdNode* nodes = nullptr;
    const HwTriangle* triangles = nullptr;
    uint64_t node_count = 0, triangle_count = 0;
    uint64_t node_base = 0;                     ///< address of node 0
    TriangleAddressing tri_at;                  ///< where triangles' bytes are (plain or compressed leaves)
    bool curved = false;                        ///< some records are curved: leaves split their tests by kind
    Aabb bounds;                                ///< the root cell
};

class BkdStepper final : public BinaryCellStepper<BkdStepper, kBkdMaxDepth> {
public:
    static constexpr const char* kName = "B-Kd tree";
    /// The cell stepper's restart path needs these; B-Kd trees offer no restart trail (their
    /// capabilities do not declare one), so the resolution step never lets a restart happen.
    static constexpr bool kPushDown = false;
    static constexpr uint32_t kNodeTests = 4;  ///< an interior node's four interval-plane tests

    explicit BkdStepper(const BkdView& view) : m_view(view) {}

    void begin(const Ray& ray, TraversalMode mode) override;
    StepOutcome execute() override;

private:
    friend class BinaryCellStepper<BkdStepper, kBkdMaxDepth>;
    enum class Phase : uint8_t { clip, node, leaf };
    void visit(uint32_t node, const detail::SlabInterval& cell);
    void plan_node(uint32_t node);
    void interior(const BkdNode& node);
    uint32_t leaf();  ///< returns the alpha tests run

    BkdView m_view;
    Phase m_phase = Phase::clip;
    uint32_t m_node = 0;
    detail::SlabInterval m_cell;
};

}  // namespace rtsim
