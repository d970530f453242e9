#pragma once
// The traversal, written once as a resumable stepper. The reference tracer runs it in a loop;
// each SystemC traversal unit drives the same stepper and adds timing, so the model fetches the
// same nodes and triangles in the same order and gets bit-identical hits (DESIGN rules 1 and 3).
//
// Closest hit with front-to-back child order: both child boxes of a node are tested, the nearer
// hit child is visited next, the farther pushed with its entry distance; popped entries farther
// than the current hit are skipped without a fetch. Any-hit stops at the first accepted hit.
// Ties in t are broken towards the smaller primitive id so the result is order-independent.
#include <cstdint>

#include "traces/bvh/hw_layout.h"
#include "traces/common/ray.h"
#include "traces/isect/ray_box.h"
#include "traces/isect/ray_triangle.h"

namespace rtsim {

enum class TraversalMode : uint8_t { closest_hit = 0, any_hit = 1 };

constexpr int kTraversalStackSize = 64;

class Traversal {
public:
    enum class Step : uint8_t {
        node,  ///< fetch HwNode node_index() and call visit_node()
        leaf,  ///< fetch leaf_count() HwTriangles from leaf_first() and call visit_leaf()
        done,  ///< hit() and work() are final
    };

    /// Starts a ray at the root (node 0). Invalid rays (ray_is_valid() false) go straight to done
    /// with a miss; the caller counts them as rejected.
    void begin(const Ray& ray, TraversalMode mode);

    Step step() const { return m_step; }
    uint32_t node_index() const { return m_ref; }
    uint32_t leaf_first() const { return m_ref; }
    uint32_t leaf_count() const { return m_count; }

    void visit_node(const HwNode& node);
    void visit_leaf(const HwTriangle* triangles);

    const Hit& hit() const { return m_hit; }
    const WorkCounts& work() const { return m_work; }
    const Ray& ray() const { return m_ray; }
    TraversalMode mode() const { return m_mode; }
    /// Entries on the traversal stack now (the model maps these onto its SRAM stack).
    int stack_size() const { return m_stack_size; }

private:
    struct StackEntry {
        uint32_t ref;
        uint32_t count;
        float tnear;
    };
    void pop_next();
    void finish();  ///< step = done; a ray without a hit reports Hit{} (t = +inf)

    Ray m_ray;
    RayBoxPre m_box;
    RayTrianglePre m_tri;
    Hit m_hit;
    float m_cull_t = 0.0f;  ///< boxes entered beyond this are culled: best t widened (see .cpp)
    WorkCounts m_work;
    TraversalMode m_mode = TraversalMode::closest_hit;
    Step m_step = Step::done;
    uint32_t m_ref = 0;
    uint32_t m_count = 0;
    int m_stack_size = 0;
    StackEntry m_stack[kTraversalStackSize];
};

/// Reference tracing of one ray through the hardware BVH: the stepper's steps fused into one
/// loop per mode (trace_ray.cpp). Same visits, hits and work counts as trace_ray_stepper.
Hit trace_ray(const HwBvh& bvh, const Ray& ray, TraversalMode mode, WorkCounts* work = nullptr);

/// The same ray driven through the Traversal stepper, step by step, as the model drives it.
/// Slower than trace_ray; the tests check the two agree on every ray.
Hit trace_ray_stepper(const HwBvh& bvh, const Ray& ray, TraversalMode mode,
                      WorkCounts* work = nullptr);

/// Brute-force closest/any hit over all triangles, same arithmetic and tie-breaking; for tests.
Hit trace_ray_brute_force(const HwBvh& bvh, const Ray& ray, TraversalMode mode);

/// Deterministic stochastic alpha test of a MASK triangle: accepts a fraction `coverage` of the
/// surface, decided by a hash of (prim, quantised u, v). Same answer in the tracer and the model.
bool alpha_test_accepts(uint32_t prim, float u, float v, uint32_t coverage_x255);

}  // namespace rtsim
