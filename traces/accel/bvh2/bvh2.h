#pragma once
// The binary BVH behind the acceleration-structure seam (docs/accel.md, docs/bvh_layout.md):
// regions "nodes" (HwNode, 64 bytes: both child boxes, one line per fetch, one issue of a 2-wide
// box pipeline) and "triangles" (HwTriangle, 48 bytes, in leaf order). Built by flattening the
// binary build tree (traces/bvh); the wide and compressed BVHs collapse the same tree.
#include <memory>
#include <string>

#include "traces/accel/accel.h"
#include "traces/accel/bvh2/bvh2_packet.h"
#include "traces/accel/bvh2/bvh2_stepper.h"
#include "traces/bvh/build_tree.h"
#include "traces/bvh/hw_layout.h"

namespace rtsim {

/// The arrays of a flattened binary BVH (addresses 0: for tests and the tracer's own use).
Bvh2View bvh2_view(const HwBvh& bvh);
/// The fused reference loop over a binary BVH: same steps, hits and work as Bvh2Stepper.
Hit trace_bvh2(const Bvh2View& bvh, const Ray& ray, TraversalMode mode, WorkCounts* work = nullptr);

/// Reference tracing through a flattened binary BVH (the fused loop).
inline Hit trace_ray(const HwBvh& bvh, const Ray& ray, TraversalMode mode, WorkCounts* work = nullptr) {
    return trace_bvh2(bvh2_view(bvh), ray, mode, work);
}
/// The same ray driven through a Bvh2Stepper step by step, as the model drives it.
Hit trace_ray_stepper(const HwBvh& bvh, const Ray& ray, TraversalMode mode, WorkCounts* work = nullptr);
/// Brute force over the BVH's triangles (traces/isect/brute_force.h).
Hit trace_ray_brute_force(const HwBvh& bvh, const Ray& ray, TraversalMode mode);

/// The image of a flattened binary BVH; stats from its BvhStats and the builder's config.
AccelImage bvh2_image(const HwBvh& bvh, const BuildConfig& config, const std::string& builder);
/// The same image, the build tree flattened straight into its regions (no HwBvh in between).
AccelImage bvh2_image(const BuildTree& tree, const Scene& scene, const BuildConfig& config,
                      const std::string& builder);

/// The locality tree of binary BVH nodes (a node brings itself and its leaf children's triangles).
LocalityTree bvh2_locality_tree(const HwNode* nodes, uint64_t count);

/// Throws rtsim::Error naming `source` and the node if the image is not a binary BVH the
/// stepper can walk: child or leaf references out of range, a child not after its parent (so
/// no cycles), a tree deeper than the traversal stack, counts out of bounds. Linear time.
void validate_bvh2(const Bvh2View& view, const std::string& source);

class Bvh2Accel final : public Accel {
public:
    Bvh2Accel(AccelImage image, const std::string& source);

    std::unique_ptr<Stepper> make_stepper(const StepOptions& options = {}) const override;
    Hit trace(const Ray& ray, TraversalMode mode, WorkCounts* work = nullptr,
              const StepOptions& options = {}) const override;
    std::unique_ptr<PacketStepper> make_packet_stepper(const StepOptions& options = {}) const override;
    void trace_packet(const Ray* rays, const TraversalMode* modes, uint32_t n, Hit* hits, WorkCounts* work,
                      PacketCounts* counts, float split_below = 0.0f, const StepOptions& options = {}) const override;
    LocalityPartition partition(uint64_t budget_bytes) const override;
    std::vector<OpKind> op_kinds() const override;
    uint32_t max_stack_entries() const override { return kTraversalStackSize; }
    const Bvh2View& view() const { return m_view; }

private:
    Bvh2View m_view;
};

}  // namespace rtsim
