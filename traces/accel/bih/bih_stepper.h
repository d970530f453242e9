#pragma once
// The BIH's stepper (docs/accel.md, "bih"). Steps:
//
//   clip       no fetch; 1 box test: the ray against the root cell
//   node       fetches the 12-byte BihNode (locality key: the node); an interior node runs 2 plane
//              tests (its clip planes' distances) and goes on to the near child, pushing the far
//              one with its interval when the ray enters both; a leaf goes on to its triangles
//   leaf       fetches the leaf's triangles (contiguous) and runs one triangle test each
//
// As in the kd-tree (kd_stepper.h), a child's interval is its parent's cut at its clip plane,
// exactly the robust box test of the child's cell (traces/isect/slab_interval.h); pending cells
// entered beyond the best hit's cull distance are dropped without a fetch. Children may overlap
// (clip[0] > clip[1]), so a hit in the near child does not end the ray by itself: the cull rule
// decides, and the closest hit by (t, prim) is the binary BVH's bit for bit.
#include <cstdint>

#include "traces/accel/bih/bih_layout.h"
#include "traces/accel/cell_stepper.h"
#include "traces/accel/leaf_blocks.h"
#include "traces/common/aabb.h"
#include "traces/common/hw_triangle.h"

namespace rtsim {

/// Where a BIH's data lives: arrays and their addresses in the memory image.
struct BihView {
    const BihNode* nodes = nullptr;
    const HwTriangle* triangles = nullptr;
    uint64_t node_count = 0, triangle_count = 0;
    uint64_t node_base = 0;                     ///< address of node 0
    TriangleAddressing tri_at;                  ///< where triangles' bytes are (plain or compressed leaves)
    bool curved = false;                        ///< some records are curved: leaves split their tests by kind
    Aabb bounds;                                ///< the root cell
};

class BihStepper final : public BinaryCellStepper<BihStepper, kBihMaxDepth> {
public:
    static constexpr const char* kName = "BIH";
    static constexpr uint32_t kNodeTests = 2;  ///< an interior node's two clip-plane tests
    static constexpr bool kPushDown = false;   ///< overlapping children: a restart trail from the root

    explicit BihStepper(const BihView& view, uint32_t short_stack_entries = 0) : m_view(view) {
        configure_short_stack(short_stack_entries);
    }

    void begin(const Ray& ray, TraversalMode mode) override;
    StepOutcome execute() override;

private:
    friend class BinaryCellStepper<BihStepper, kBihMaxDepth>;
    enum class Phase : uint8_t { clip, node, leaf };
    void visit(uint32_t node, const detail::SlabInterval& cell);
    void plan_node(uint32_t node);
    void interior(const BihNode& node);
    uint32_t leaf();  ///< returns the alpha tests run

    BihView m_view;
    Phase m_phase = Phase::clip;
    uint32_t m_node = 0;
    detail::SlabInterval m_cell;
};

}  // namespace rtsim
