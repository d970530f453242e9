// Refitting a binary build tree (refit.h).
#include "traces/bvh/refit.h"

#include <cmath>

#include "traces/common/error.h"

namespace rtsim {

namespace {

/// Box of one triangle, refusing a non-finite vertex (a refit must never produce a box that
/// silently misses a triangle).
Aabb triangle_box(const Triangle& t, uint32_t prim) {
    for (const Vec3* v : {&t.v0, &t.v1, &t.v2})
        require(std::isfinite(v->x) && std::isfinite(v->y) && std::isfinite(v->z),
                "refit: triangle " + std::to_string(prim) + " has a non-finite vertex");
    Aabb b;
    b.grow(t.v0);
    b.grow(t.v1);
    b.grow(t.v2);
    return b;
}

double area(const Aabb& box) {
    if (box.empty()) return 0.0;
    const glm::dvec3 e = glm::dvec3(box.hi) - glm::dvec3(box.lo);  // double: float products overflow
    return e.x * e.y + e.y * e.z + e.z * e.x;
}

}  // namespace

BuildTree refit_build_tree(const BuildTree& topology, const std::vector<Triangle>& triangles) {
    BuildTree out = topology;
    for (uint32_t p : out.prim_ids)
        require(p < triangles.size(), "refit: the tree names primitive " + std::to_string(p) + " of " +
                                          std::to_string(triangles.size()) + " (built over other geometry?)");
    // Parents after their children: a depth-first order reversed (builders allocate children in
    // pairs but not always after their parent, so the order is taken from the tree itself).
    std::vector<uint32_t> order, stack{0};
    order.reserve(out.nodes.size());
    while (!stack.empty()) {
        const uint32_t i = stack.back();
        stack.pop_back();
        order.push_back(i);
        const BuildNode& n = out.nodes[i];
        if (n.is_leaf()) continue;
        require(n.first + 1 < out.nodes.size() && order.size() <= out.nodes.size(),
                "refit: node " + std::to_string(i) + " has children out of range");
        stack.push_back(n.first);
        stack.push_back(n.first + 1);
    }
    for (size_t k = order.size(); k-- > 0;) {
        BuildNode& n = out.nodes[order[k]];
        Aabb box;
        if (n.is_leaf()) {
            for (uint32_t j = n.first; j < n.first + n.count; ++j)
                box.grow(triangle_box(triangles[out.prim_ids[j]], out.prim_ids[j]));
        } else {
            box.grow(out.nodes[n.first].box);
            box.grow(out.nodes[n.first + 1].box);
        }
        n.box = box;
    }
    return out;
}

size_t refit_node_count(const BuildTree& tree) { return tree.nodes.size(); }

double sah_cost(const BuildTree& tree, const BuildConfig& config) {
    if (tree.nodes.empty()) return 0.0;
    const double root = area(tree.nodes[0].box);
    double cost = 0.0;
    for (const BuildNode& n : tree.nodes) {
        const double w = root > 0.0 ? area(n.box) / root : 1.0;
        cost += (n.is_leaf() ? double(config.intersection_cost) * n.count : double(config.traversal_cost)) * w;
    }
    return cost;
}

}  // namespace rtsim
