// The traversal stepper (traversal.h) and the loops built on it. The order of visits and the
// work counted here are the definition the SystemC model matches (docs/intersection.md).
#include "traces/isect/traversal.h"

#include <cmath>
#include <string>
#include <vector>

#include "traces/common/error.h"
#include "traces/common/rng.h"
#include "traces/isect/ray_box_kernel.h"

namespace rtsim {

namespace {

/// Closest-hit order on (t, prim): nearer first, ties to the smaller primitive id. A best prim
/// of -1 (no hit yet) compares as the largest unsigned id, so a hit at exactly tmax is accepted.
inline bool closer(float t, uint32_t prim, float best_t, int32_t best_prim) {
    return t < best_t || (t == best_t && prim < uint32_t(best_prim));
}

/// Culling distance for a best hit at t: t widened by a relative 2^-10. The watertight t has an
/// error of a few ulps of the triangle's largest ray-space depth, while a box's entry distance
/// is good to gamma(3); a hit that ties with (or beats) the best may lie on its box's boundary,
/// e.g. at a shared vertex. Culling at t itself could then drop it, and the result would depend
/// on the visit order. The margin covers depth/t ratios up to about 1000 and costs a visit only
/// for boxes entered within 0.1% behind the best hit.
inline float cull_distance(float t) { return t + std::fabs(t) * 0x1p-10f; }

}  // namespace

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
    unsigned mask = detail::node_kernel(m_box, node, m_ray.tmin, m_cull_t, tnear);
    // Empty slots never hit, whatever their box holds.
    if (node.child_count[0] == kEmptyChild) mask &= ~1u;
    if (node.child_count[1] == kEmptyChild) mask &= ~2u;
    if (mask == 0) {
        pop_next();
        return;
    }
    // Nearer child next (child 0 on equal entry distances); push the farther one.
    int next = mask == 2 ? 1 : 0;
    if (mask == 3) {
        const int far = tnear[1] < tnear[0] ? 0 : 1;
        next = 1 - far;
        if (m_stack_size >= kTraversalStackSize)
            throw Error("traversal stack overflow (" + std::to_string(kTraversalStackSize) +
                        " entries): BVH deeper than the builder's max_depth allows");
        m_stack[m_stack_size++] = {node.child_ref[far], node.child_count[far], tnear[far]};
    }
    m_ref = node.child_ref[next];
    m_count = node.child_count[next];
    m_step = m_count == 0 ? Step::node : Step::leaf;
}

void Traversal::visit_leaf(const HwTriangle* triangles) {
    m_work.tri_tests += m_count;
    for (uint32_t i = 0; i < m_count; ++i) {
        const HwTriangle& tri = triangles[i];
        // Tested against the ray's own interval so acceptance never depends on visit order;
        // the (t, prim) comparison below then picks the closest (ties: smaller prim).
        TriangleHit th;
        if (!intersect_triangle(m_tri, tri.v0, tri.v1, tri.v2, m_ray.tmin, m_ray.tmax, &th))
            continue;
        if (m_mode == TraversalMode::closest_hit && !closer(th.t, tri.prim, m_hit.t, m_hit.prim))
            continue;
        // Alpha-MASK triangles: the any-hit (alpha) test decides.
        if (tri.flags & kTriAnyHit) {
            m_work.anyhit_calls += 1;
            const uint32_t coverage = (tri.flags >> kTriCoverageShift) & 0xFFu;
            if (!alpha_test_accepts(tri.prim, th.u, th.v, coverage)) continue;
        }
        m_hit.prim = int32_t(tri.prim);
        m_hit.inst = int32_t(tri.inst);
        m_hit.t = th.t;
        m_hit.u = th.u;
        m_hit.v = th.v;
        m_cull_t = cull_distance(th.t);
        if (m_mode == TraversalMode::any_hit) {
            finish();
            return;
        }
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

#if defined(__GNUC__)
// Inline the stepper's visits into this loop (same code, no call per node).
__attribute__((flatten))
#endif
Hit trace_ray(const HwBvh& bvh, const Ray& ray, TraversalMode mode, WorkCounts* work) {
    // An empty scene has no root: every ray misses without work.
    if (bvh.nodes.empty()) {
        if (work) *work = WorkCounts{};
        return Hit{};
    }
    Traversal tr;
    tr.begin(ray, mode);
    const HwNode* nodes = bvh.nodes.data();
    const HwTriangle* tris = bvh.triangles.data();
    for (;;) {
        const Traversal::Step step = tr.step();
        if (step == Traversal::Step::node)
            tr.visit_node(nodes[tr.node_index()]);
        else if (step == Traversal::Step::leaf)
            tr.visit_leaf(tris + tr.leaf_first());
        else
            break;
    }
    if (work) *work = tr.work();
    return tr.hit();
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
