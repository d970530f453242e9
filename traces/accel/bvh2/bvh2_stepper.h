#pragma once
// The binary BVH's stepper (docs/intersection.md): closest hit with front-to-back child order.
// Both child boxes of a node are tested, the nearer hit child is visited next, the farther
// pushed with its entry distance; popped entries farther than the current hit are skipped
// without a fetch. Any-hit stops at the first accepted hit. Ties in t are broken towards the
// smaller primitive id so the result is order-independent.
//
// Steps: a node step fetches one 64-byte HwNode and runs 2 box tests (locality key: the node);
// a leaf step fetches its HwTriangles (contiguous) and runs one triangle test each, plus an
// alpha test for each MASK triangle hit (reported by execute()).
//
// An oriented node (obvh2) is one step of the same fetch with a ray rotation (an `obb`
// operation) ahead of its 2 box tests, which run in the node's frame.
//
// With a short stack (set by the Accel; traces/accel/short_stack.h) a restart's re-descent adds
// node steps of the same shape, counted in the model-only restart fields. With reduced-precision
// box tests (traces/accel/rp_boxes.h) the subtrees only the narrower test enters add node and
// leaf steps of the same shapes, counted in the model-only rp_* fields.
#include <cstdint>

#include "traces/accel/bvh2/bvh2_kernel.h"
#include "traces/accel/leaf_blocks.h"
#include "traces/accel/obvh/obvh_rotate.h"
#include "traces/accel/rp_boxes.h"
#include "traces/accel/short_stack.h"
#include "traces/accel/stepper.h"
#include "traces/bvh/hw_layout.h"
#include "traces/isect/ray_box.h"
#include "traces/isect/ray_triangle.h"

namespace rtsim {

/// Where a binary BVH's data lives: arrays and their addresses in the memory image.
struct Bvh2View {
    const HwNode* nodes = nullptr;
    const HwTriangle* triangles = nullptr;
    uint64_t node_count = 0;
    uint64_t triangle_count = 0;
    uint64_t node_base = 0;      ///< address of node 0
    TriangleAddressing tri_at;   ///< where triangles' bytes are (plain or compressed leaves)
    bool curved = false;         ///< some records are curved: leaves split their tests by kind
    /// Oriented nodes only (obvh2, traces/accel/obvh/obvh.h): node i's child boxes lie in the
    /// frame of row-major 3x3 rotation_table[9 * rotations[i]] (kNoRotation: the world's axes).
    const uint8_t* rotations = nullptr;
    const float* rotation_table = nullptr;
    float scene_radius = 0.0f;  ///< every point of the scene within it of the origin (the rotation's error bound)

    bool oriented(uint32_t node) const { return rotations && rotations[node] != kNoRotation; }
};

namespace detail {
/// Oriented node `ref` as a ray sees it (the single-ray and the packet steppers alike): the ray
/// rotated into the node's frame with its box precompute, and the node's child boxes widened by
/// the ray's pad (obb_pad), so the test stays conservative.
struct OrientedNode {
    RayBoxPre pre;
    HwNode node;
};
inline OrientedNode oriented_node(const Bvh2View& v, uint32_t ref, const Ray& ray, float pad) {
    const float* m = v.rotation_table + 9 * size_t(v.rotations[ref]);
    Ray local = ray;
    local.origin = obb_rotate(m, ray.origin);
    local.direction = obb_rotate(m, ray.direction);
    OrientedNode o{ray_box_precompute(local), v.nodes[ref]};
    for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 2; ++c) o.node.lo(c, a) -= pad, o.node.hi(c, a) += pad;
    return o;
}
}  // namespace detail

class Bvh2Stepper final : public Stepper {
public:
    explicit Bvh2Stepper(const Bvh2View& view, uint32_t short_stack_entries = 0, uint32_t box_precision_bits = 0,
                         AnyHitOrder anyhit_order = AnyHitOrder::nearest)
        : m_view(view), m_anyhit_order(anyhit_order) {
        m_short.configure(short_stack_entries);
        m_rp.configure(box_precision_bits);
    }

    void begin(const Ray& ray, TraversalMode mode) override;
    StepOutcome execute() override;
    uint32_t stack_reads(Fetch* out, uint32_t max) const override;

private:
    void visit_node(const HwNode& node);
    uint32_t visit_leaf(const HwTriangle* triangles);
    void pop_next();
    void plan_next() { plan_at(m_ref, m_count); }
    void plan_at(uint32_t ref, uint32_t count);  ///< a node (count 0) or a leaf's triangles
    void begin_restart(uint32_t depth, bool resume);
    void plan_replay();  ///< the next node a short stack's restart revisits
    void replay_step();
    /// Reduced-precision boxes: tests both children with the narrower test, hands the boxes only
    /// it accepts to m_rp and writes its entry distances.
    void rp_tests(const HwNode& node, const RayBoxPre& pre, float tnear[2]);
    void rp_step();  ///< one step of the extra walk (rp_boxes.h)
    void finish();  ///< the plan is done; a ray without a hit reports Hit{} (t = +inf)
    /// An oriented node's step: the ray rotated into its frame, its boxes widened (obvh_rotate.h).

    Bvh2View m_view;
    AnyHitOrder m_anyhit_order;  ///< child order of any-hit rays (closest-hit: nearest first)
    RayBoxPre m_box;
    RayTrianglePre m_tri;
    float m_cull_t = 0.0f;  ///< boxes entered beyond this are culled: best t widened
    float m_obb_pad = 0.0f;  ///< oriented nodes: how far their boxes are widened for this ray
    uint32_t m_ref = 0;     ///< node index, or first triangle of a leaf
    uint32_t m_count = 0;   ///< 0: m_ref is a node; else the leaf's triangle count
    detail::Bvh2StackEntry m_stack[kTraversalStackSize];
    // Short stack only: the current node's depth, each entry's depth, and the shadow.
    uint32_t m_depth = 0;
    bool m_resume = false;  ///< after the re-descent: m_ref/m_count (true) or the end (false)
    uint32_t m_entry_depth[kTraversalStackSize];
    ShortStack m_short;
    // Reduced-precision boxes only: each entry's entry distance by the narrower test, and the shadow.
    float m_rp_tnear[kTraversalStackSize];
    ReducedPrecisionBoxes m_rp;
};

}  // namespace rtsim
