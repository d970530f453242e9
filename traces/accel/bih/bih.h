#pragma once
// The bounding interval hierarchy behind the acceleration-structure seam (docs/accel.md, "bih"):
// two clip planes per node on one axis, every triangle stored once (no references, no
// duplication), front-to-back traversal of (node, tnear, tfar) with two ray/plane tests per
// interior node on the `plane` pipeline. Builders: "binned" (the default) and "lbvh" convert a
// binary BVH build tree node by node (per node the axis and child order whose clip planes leave
// the cheapest cells by the SAH); "wachter_keller" is the paper's global heuristic (the middle of
// the current split box, triangles by their box centres).
#include <memory>
#include <string>
#include <vector>

#include "traces/accel/accel.h"
#include "traces/accel/bih/bih_layout.h"
#include "traces/accel/bih/bih_stepper.h"
#include "traces/bvh/build_tree.h"

namespace rtsim {

struct Scene;

/// A built BIH before it becomes an image: nodes (children in adjacent pairs) whose leaves
/// index ranges of prim_ids.
struct BihTree {
    std::vector<BihNode> nodes;
    std::vector<uint32_t> prim_ids;
    Aabb bounds;
};

/// Wachter & Keller 2006's build over a flattened scene's triangles. Deterministic.
BihTree build_bih(const Scene& scene, const BihConfig& config = {});
/// A BIH from a binary BVH build tree (binned SAH, LBVH): same leaves, clip planes from the
/// children's boxes on the axis (and in the order) that leaves the cheapest cells.
BihTree bih_from_build_tree(const BuildTree& tree);
/// The image: regions nodes and triangles (in prim_ids order); params {"bounds": [lo, hi]}.
AccelImage bih_image(const BihTree& tree, const Scene& scene, const std::string& builder);

/// Throws rtsim::Error naming `source` and the record if the view is not a BIH the stepper can
/// walk: a child pair not after its parent or out of range, a node with two parents or none,
/// a NaN clip plane, a leaf outside the triangles, a triangle in no leaf or two, a tree deeper than
/// kBihMaxDepth. Linear time. Returns the depth.
uint32_t validate_bih(const BihView& view, const std::string& source);

/// Throws rtsim::Error naming the first broken invariant of a built BIH: a triangle outside the
/// cell of its leaf or beyond a clip plane of an ancestor (its side's), triangle records that are
/// not a permutation of the scene's.
void check_bih_invariants(const BihView& view, const Scene& scene);

class BihAccel final : public Accel {
public:
    BihAccel(AccelImage image, const std::string& source);

    std::unique_ptr<Stepper> make_stepper(const StepOptions& options = {}) const override;
    /// Packets of rays sharing one walk (cell_packet.h), each ray with its own mailbox.
    std::unique_ptr<PacketStepper> make_packet_stepper(const StepOptions& options = {}) const override;
    Hit trace(const Ray& ray, TraversalMode mode, WorkCounts* work = nullptr,
              const StepOptions& options = {}) const override;
    LocalityPartition partition(uint64_t budget_bytes) const override;
    std::vector<OpKind> op_kinds() const override;
    uint32_t max_stack_entries() const override { return m_depth; }
    const BihView& view() const { return m_view; }

private:
    BihView m_view;
    uint32_t m_depth = 0;
};

}  // namespace rtsim
