// The traversal stepper (traversal.h), brute force and the alpha test. The order of visits and
// the work counted here are the definition the SystemC model matches (docs/intersection.md);
// trace_ray (trace_ray.cpp) fuses the same steps into one loop.
#include "traces/isect/traversal.h"

#include <cmath>
#include <string>
#include <vector>

#include "traces/common/error.h"
#include "traces/common/rng.h"
#include "traces/isect/traversal_kernel.h"

namespace rtsim {

using detail::closer;
using detail::cull_distance;

namespace detail {

void throw_stack_overflow() {
    throw Error("traversal stack overflow (" + std::to_string(kTraversalStackSize) +
                " entries): BVH deeper than the builder's max_depth allows");
}

}  // namespace detail

void Traversal::begin(const Ray& ray, TraversalMode mode) {
    m_ray = ray;
    m_mode = mode;
    m_hit = Hit{};
    m_work = WorkCounts{};
    m_stack_size = 0;
    if (!ray_is_valid(ray)) {
        finish();
        return;
    }
    m_box = ray_box_precompute(ray);
    m_tri = ray_triangle_precompute(ray);
    // While traversing, m_hit.t is the current best distance (the shrinking tmax).
    m_hit.t = ray.tmax;
    m_cull_t = cull_distance(ray.tmax);
    m_ref = 0;
    m_count = 0;
    m_step = Step::node;
}

void Traversal::visit_node(const HwNode& node) {
    m_work.nodes += 1;
    m_work.box_tests += 2;
    float tnear[2];
    const unsigned mask = detail::node_step(m_box, node, m_ray.tmin, m_cull_t, tnear);
    if (mask == 0) {
        pop_next();
        return;
    }
    const unsigned next = detail::next_slot(mask, tnear);
    // Nearer child next (child 0 on equal entry distances); push the farther one.
    if (mask == 3) {
        const unsigned far = next ^ 1u;
        if (m_stack_size >= kTraversalStackSize) detail::throw_stack_overflow();
        m_stack[m_stack_size++] = {node.child_ref[far], node.child_count[far], tnear[far]};
    }
    m_ref = node.child_ref[next];
    m_count = node.child_count[next];
    m_step = m_count == 0 ? Step::node : Step::leaf;
}

void Traversal::visit_leaf(const HwTriangle* triangles) {
    m_work.tri_tests += m_count;
    const bool done =
        m_mode == TraversalMode::any_hit
            ? detail::leaf_step<true>(m_tri, m_ray.tmin, m_ray.tmax, triangles, m_count, m_hit,
                                      m_cull_t, m_work.anyhit_calls)
            : detail::leaf_step<false>(m_tri, m_ray.tmin, m_ray.tmax, triangles, m_count, m_hit,
                                       m_cull_t, m_work.anyhit_calls);
    if (done) {
        finish();
        return;
    }
    pop_next();
}

void Traversal::pop_next() {
    // Entries entered beyond the (widened) best hit are dropped without a fetch.
    while (m_stack_size > 0) {
        const StackEntry& e = m_stack[--m_stack_size];
        if (e.tnear > m_cull_t) continue;
        m_ref = e.ref;
        m_count = e.count;
        m_step = e.count == 0 ? Step::node : Step::leaf;
        return;
    }
    finish();
}

void Traversal::finish() {
    if (m_hit.prim < 0) m_hit = Hit{};
    m_step = Step::done;
}

Hit trace_ray_brute_force(const HwBvh& bvh, const Ray& ray, TraversalMode mode) {
    Hit best;
    if (!ray_is_valid(ray)) return best;
    const RayTrianglePre pre = ray_triangle_precompute(ray);
    best.t = ray.tmax;
    // Triangles in primitive-id order, whatever order the BVH stores them in.
    std::vector<const HwTriangle*> order(bvh.triangles.size());
    for (const HwTriangle& tri : bvh.triangles) order.at(tri.prim) = &tri;
    for (const HwTriangle* tri : order) {
        TriangleHit th;
        if (!intersect_triangle(pre, tri->v0, tri->v1, tri->v2, ray.tmin, ray.tmax, &th)) continue;
        if (mode == TraversalMode::closest_hit && !closer(th.t, tri->prim, best.t, best.prim))
            continue;
        if ((tri->flags & kTriAnyHit) &&
            !alpha_test_accepts(tri->prim, th.u, th.v, (tri->flags >> kTriCoverageShift) & 0xFFu))
            continue;
        best = Hit{int32_t(tri->prim), int32_t(tri->inst), th.t, th.u, th.v};
        if (mode == TraversalMode::any_hit) break;
    }
    if (best.prim < 0) best = Hit{};
    return best;
}

bool alpha_test_accepts(uint32_t prim, float u, float v, uint32_t coverage_x255) {
    if (coverage_x255 >= 255) return true;
    if (coverage_x255 == 0) return false;
    // u, v quantised to 1/1024 so tiny arithmetic differences cannot flip the decision.
    const auto quantise = [](float x) { return uint64_t(int64_t(std::floor(x * 1024.0f)) & 0x7FF); };
    const uint64_t h = hash_combine(0xA1FAu, prim, quantise(u), quantise(v));
    return hash_to_unit(h) * 255.0f < float(coverage_x255);
}

}  // namespace rtsim
