#pragma once
// The kd-tree behind the acceleration-structure seam (docs/accel.md, "kdtree"): SAH splits found
// by the O(N log N) event sweep of Wald & Havran 2006 with perfect splits (straddling triangles
// clipped to the child cells) and the empty-space bonus; 8-byte nodes (kd_layout.h); front-to-back
// traversal of (node, tnear, tfar) with one ray/plane test per interior node on the `plane`
// pipeline, ending at the first hit that lies inside the current leaf.
#include <memory>
#include <string>
#include <vector>

#include "traces/accel/accel.h"
#include "traces/accel/kdtree/kd_layout.h"
#include "traces/accel/kdtree/kd_stepper.h"

namespace rtsim {

struct Scene;

/// A built kd-tree before it becomes an image (the builder's output; tests inspect it).
struct KdTreeBuild {
    std::vector<KdNode> nodes;
    std::vector<uint32_t> refs;
    Aabb bounds;                 ///< the root cell
    nlohmann::json stats;        ///< what the manifest records
};

/// Builds the kd-tree over a flattened scene's triangles. Deterministic. Throws rtsim::Error on a
/// non-finite vertex, an empty scene or a tree that would not fit the layout.
KdTreeBuild build_kdtree(const Scene& scene, const KdConfig& config = {});
/// The image: regions nodes, prim_refs, triangles; params {"bounds": [lo, hi]}.
AccelImage kdtree_image(const Scene& scene, const KdConfig& config = {});

/// Throws rtsim::Error naming `source` and the record if the view is not a kd-tree the stepper
/// can walk: a child not after its parent or out of range, a node with two parents or none, a
/// non-finite split or one outside its cell, a list outside prim_refs, a reference outside
/// triangles, a tree deeper than kKdMaxDepth. Linear time. Returns the depth.
uint32_t validate_kdtree(const KdView& view, const std::string& source);

/// Throws rtsim::Error naming the first broken invariant of a built kd-tree: a triangle record
/// that is not the scene's, a list not increasing, a triangle missing from a leaf whose cell its
/// part overlaps by more than rounding (it must be listed in every leaf where it has area).
void check_kdtree_invariants(const KdView& view, const Scene& scene);

class KdAccel final : public Accel {
public:
    KdAccel(AccelImage image, const std::string& source);

    std::unique_ptr<Stepper> make_stepper(const StepOptions& options = {}) const override;
    /// Packets of rays sharing one walk (cell_packet.h), each ray with its own mailbox.
    std::unique_ptr<PacketStepper> make_packet_stepper(const StepOptions& options = {}) const override;
    Hit trace(const Ray& ray, TraversalMode mode, WorkCounts* work = nullptr,
              const StepOptions& options = {}) const override;
    LocalityPartition partition(uint64_t budget_bytes) const override;
    std::vector<OpKind> op_kinds() const override;
    uint32_t max_stack_entries() const override { return m_depth; }
    const KdView& view() const { return m_view; }

private:
    KdView m_view;
    uint32_t m_depth = 0;
};

}  // namespace rtsim
