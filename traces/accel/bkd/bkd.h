#pragma once
// The B-Kd tree behind the acceleration-structure seam (Woop, Marmitt & Slusallek 2006;
// docs/accel.md, "bkd"): two bounding intervals per node on one axis (four planes), every
// triangle stored once (no references, no duplication), front-to-back traversal of (node, tnear,
// tfar) with four ray/plane tests per interior node on the `plane` pipeline. Its builders convert
// a binary BVH build tree node by node (any tree builder: binned, sweep, median, lbvh), per node
// on the axis whose two intervals leave the cheapest cells by the SAH. Woop et al. build with
// the SAH and refit the intervals for dynamic scenes; the refit is not modelled here.
#include <memory>
#include <string>
#include <vector>

#include "traces/accel/accel.h"
#include "traces/accel/bkd/bkd_layout.h"
#include "traces/accel/bkd/bkd_stepper.h"
#include "traces/bvh/build_tree.h"

namespace rtsim {

struct Scene;

/// A built B-Kd tree before it becomes an image: nodes (children in adjacent pairs) whose leaves
/// index ranges of prim_ids.
struct BkdTree {
    std::vector<BkdNode> nodes;
    std::vector<uint32_t> prim_ids;
    Aabb bounds;
};

/// A B-Kd tree from a binary BVH build tree: same leaves; per node the children's intervals on
/// the axis whose cells are cheapest by the SAH, the child lower on that axis first.
BkdTree bkd_from_build_tree(const BuildTree& tree);
/// The image: regions nodes and triangles (in prim_ids order); params {"bounds": [lo, hi]}.
AccelImage bkd_image(const BkdTree& tree, const Scene& scene, const std::string& builder);

/// Throws rtsim::Error naming `source` and the record if the view is not a B-Kd tree the stepper can
/// walk: a child pair not after its parent or out of range, a node with two parents or none,
/// a NaN plane, a leaf outside the triangles, a triangle in no leaf or two, a tree deeper than
/// kBkdMaxDepth. Linear time. Returns the depth.
uint32_t validate_bkd(const BkdView& view, const std::string& source);

/// Throws rtsim::Error naming the first broken invariant of a built B-Kd tree: a triangle outside
/// the cell of its leaf (its ancestors' intervals), triangle records that are not a permutation
/// of the scene's.
void check_bkd_invariants(const BkdView& view, const Scene& scene);

class BkdAccel final : public Accel {
public:
    BkdAccel(AccelImage image, const std::string& source);

    std::unique_ptr<Stepper> make_stepper(const StepOptions& options = {}) const override;
    std::unique_ptr<PacketStepper> make_packet_stepper(const StepOptions& options = {}) const override;
    Hit trace(const Ray& ray, TraversalMode mode, WorkCounts* work = nullptr,
              const StepOptions& options = {}) const override;
    LocalityPartition partition(uint64_t budget_bytes) const override;
    std::vector<OpKind> op_kinds() const override;
    uint32_t max_stack_entries() const override { return m_depth; }
    const BkdView& view() const { return m_view; }

private:
    BkdView m_view;
    uint32_t m_depth = 0;
};

}  // namespace rtsim
