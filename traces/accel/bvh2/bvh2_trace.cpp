// The binary BVH's fused reference loop: the stepper's node and leaf steps (bvh2_kernel.h)
// fused into one loop, specialised per mode, with the per-ray state in registers and local
// counters. It visits the same nodes in the same order and keeps the same hits and work counts
// as driving the stepper; test_trace_ray_equivalence checks that ray by ray.
#include "traces/accel/bvh2/bvh2.h"
#include "traces/accel/bvh2/bvh2_kernel.h"

// Hides a value from the optimiser so it keeps a branch rather than a conditional move.
#if defined(__GNUC__)
#define RTSIM_OPAQUE(x) __asm__("" : "+r"(x))
#else
#define RTSIM_OPAQUE(x) (void)(x)
#endif

namespace rtsim {
namespace {

template <bool kAnyHit>
Hit trace_fused(const Bvh2View& bvh, const Ray& ray, WorkCounts* work) {
    // An empty scene has no root, and an invalid ray is never traversed: a miss, no work.
    if (bvh.node_count == 0 || !ray_is_valid(ray)) {
        if (work) *work = WorkCounts{};
        return Hit{};
    }
    const HwNode* const nodes = bvh.nodes;
    const HwTriangle* const tris = bvh.triangles;
    const RayBoxPre box = ray_box_precompute(ray);
    const RayTrianglePre tri = ray_triangle_precompute(ray);
    const float tmin = ray.tmin, tmax = ray.tmax;
    Hit best;
    best.t = tmax;
    float cull = detail::cull_distance(tmax);
#if defined(__SSE2__)
    const __m128 tmin4 = _mm_set1_ps(tmin);
    __m128 cull4 = _mm_set1_ps(cull);
#endif
    uint32_t node_visits = 0, tri_tests = 0, sphere_tests = 0, capsule_tests = 0, anyhit_calls = 0;

    struct Entry {
        uint32_t ref, count;
        float tnear;
    } stack[kTraversalStackSize];
    int size = 0;
    uint32_t ref = 0, count = 0;  // the root, node 0
    for (;;) {
        if (count == 0) {
            const HwNode& node = nodes[ref];
            node_visits += 1;
            float tnear[2];
#if defined(__SSE2__)
            __m128 tn;
            const unsigned mask = detail::node_step_sse(box, node, tmin4, cull4, &tn);
            tnear[0] = _mm_cvtss_f32(tn);
            tnear[1] = _mm_cvtss_f32(_mm_shuffle_ps(tn, tn, 1));
#else
            const unsigned mask = detail::node_step(box, node, tmin, cull, tnear);
#endif
            if (mask != 0) {
                // detail::next_slot written out as branches: a predicted branch lets the next
                // node's fetch start before this node's box test has finished.
                unsigned next;
                if (mask == 1) {
                    next = 0;
                    RTSIM_OPAQUE(next);
                } else if (mask == 2) {
                    next = 1;
                    RTSIM_OPAQUE(next);
                } else {
                    if (tnear[1] < tnear[0]) {
                        next = 1;
                    } else {
                        next = 0;
                        RTSIM_OPAQUE(next);
                    }
                    const unsigned far = next ^ 1u;
                    if (size >= kTraversalStackSize) detail::throw_stack_overflow();
                    stack[size++] = {node.child_ref[far], node.child_count[far], tnear[far]};
                }
                ref = node.child_ref[next];
                count = node.child_count[next];
                continue;
            }
        } else {
            const detail::LeafTests kinds = detail::leaf_tests(tris + ref, count, bvh.curved);
            tri_tests += kinds.triangles;
            sphere_tests += kinds.spheres;
            capsule_tests += kinds.capsules;
            if (detail::leaf_step<kAnyHit>(tri, tmin, tmax, tris + ref, count, best, cull,
                                           anyhit_calls))
                break;
#if defined(__SSE2__)
            cull4 = _mm_set1_ps(cull);
#endif
        }
        // Pop: entries entered beyond the (widened) best hit are dropped without a fetch.
        for (;;) {
            if (size == 0) goto done;
            const Entry& e = stack[--size];
            if (e.tnear > cull) continue;
            ref = e.ref;
            count = e.count;
            break;
        }
    }
done:
    if (work) {
        *work = WorkCounts{};
        work->steps = node_visits;
        work->box_tests = 2 * node_visits;
        work->tri_tests = tri_tests;
        work->sphere_tests = sphere_tests;
        work->capsule_tests = capsule_tests;
        work->anyhit_calls = anyhit_calls;
    }
    if (best.prim < 0) best = Hit{};
    return best;
}

}  // namespace

Hit trace_bvh2(const Bvh2View& bvh, const Ray& ray, TraversalMode mode, WorkCounts* work) {
    return mode == TraversalMode::any_hit ? trace_fused<true>(bvh, ray, work)
                                          : trace_fused<false>(bvh, ray, work);
}

}  // namespace rtsim
