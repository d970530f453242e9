// Invariant checker and SAH cost of a flattened BVH. Both read only the hardware layout, so they
// judge what the tracer and the model will actually fetch, whatever builder made it.
#include <cstring>
#include <string>
#include <vector>

#include "traces/bvh/build_tree.h"
#include "traces/bvh/builder.h"
#include "traces/bvh/sbvh_clip.h"
#include "traces/common/error.h"

namespace rtsim {
namespace {

/// Equals kTraversalStackSize (traces/isect/traversal.h).
constexpr uint32_t kMaxLeafDepth = 64;

Aabb slot_box(const HwNode& node, int slot) {
    return Aabb{Vec3(node.lo(slot, 0), node.lo(slot, 1), node.lo(slot, 2)),
                Vec3(node.hi(slot, 0), node.hi(slot, 1), node.hi(slot, 2))};
}

bool inside(const Aabb& box, const float* v) {
    return box.lo.x <= v[0] && v[0] <= box.hi.x && box.lo.y <= v[1] && v[1] <= box.hi.y &&
           box.lo.z <= v[2] && v[2] <= box.hi.z;
}

bool same_vertex(const float* hw, const Vec3& v) {
    float s[3] = {v.x, v.y, v.z};
    return std::memcmp(hw, s, sizeof(s)) == 0;
}
bool same_vertex(const float* hw, const float* want) { return std::memcmp(hw, want, 3 * sizeof(float)) == 0; }

struct Checker {
    const HwBvh& bvh;
    const Scene& scene;
    bool spatial_splits;
    std::vector<uint8_t> node_seen, tri_seen, prim_seen;
    std::vector<double> covered;  ///< spatial splits: area of each primitive inside its leaf boxes
    struct Item {
        uint32_t node;
        Aabb parent;
        uint32_t depth;
    };
    std::vector<Item> stack;

    void check_leaf(uint32_t node, int slot, const Aabb& box, uint32_t depth);
    void check_slot(uint32_t node, int slot, const Aabb& parent, uint32_t depth);
    void run();
};

[[noreturn]] void fail(uint32_t node, int slot, const std::string& what) {
    throw Error("BVH node " + std::to_string(node) + " child " + std::to_string(slot) + ": " + what);
}

std::string triangle_name(uint64_t j, uint32_t prim) {
    return "triangle " + std::to_string(j) + " (prim " + std::to_string(prim) + ")";
}

// A leaf slot: in range, each triangle referenced once, inside the box, equal to its scene
// primitive (same vertex bits and instance).
void Checker::check_leaf(uint32_t node, int slot, const Aabb& box, uint32_t depth) {
    const HwNode& n = bvh.nodes[node];
    uint64_t first = n.child_ref[slot], count = n.child_count[slot];
    if (first + count > bvh.triangles.size())
        fail(node, slot, "leaf triangles " + std::to_string(first) + "+" + std::to_string(count) +
                             " beyond the " + std::to_string(bvh.triangles.size()) + " triangles");
    if (depth > kMaxLeafDepth)
        fail(node, slot, "leaf at depth " + std::to_string(depth) +
                             " deeper than the traversal stack (64)");
    for (uint64_t j = first; j < first + count; ++j) {
        const HwTriangle& t = bvh.triangles[j];
        if (tri_seen[j]) fail(node, slot, triangle_name(j, t.prim) + " referenced twice");
        tri_seen[j] = 1;
        if (t.prim >= scene.triangles.size())
            fail(node, slot, triangle_name(j, t.prim) + ": no such primitive in the scene");
        const Triangle& s = scene.triangles[t.prim];
        if (spatial_splits) {
            Aabb tri_box;
            tri_box.grow(s.v0), tri_box.grow(s.v1), tri_box.grow(s.v2);
            const Aabb common{glm::max(tri_box.lo, box.lo), glm::min(tri_box.hi, box.hi)};
            if (common.empty()) fail(node, slot, triangle_name(j, t.prim) + " does not overlap the leaf box");
            covered[t.prim] += ClippedTriangle(s, box).area();
        } else {
            // A triangle's own vertices; a curved primitive's box corners, from the scene (scene.h).
            const float* p[3] = {t.v0, t.v1, t.v2};
            if (is_curved(t)) p[0] = &s.v0.x, p[1] = &s.v1.x, p[2] = &s.v2.x;
            if (!inside(box, p[0]) || !inside(box, p[1]) || !inside(box, p[2]))
                fail(node, slot, triangle_name(j, t.prim) + " outside the leaf box");
            if (prim_seen[t.prim]) fail(node, slot, triangle_name(j, t.prim) + ": primitive stored twice");
        }
        prim_seen[t.prim] = 1;
        const HwTriangle want = make_hw_triangle(scene, t.prim);
        if (!same_vertex(t.v0, want.v0) || !same_vertex(t.v1, want.v1) || !same_vertex(t.v2, want.v2) ||
            t.inst != want.inst || is_sphere(t) != is_sphere(want) || is_capsule(t) != is_capsule(want))
            fail(node, slot, triangle_name(j, t.prim) + " differs from the scene's primitive");
    }
}

void Checker::check_slot(uint32_t node, int slot, const Aabb& parent, uint32_t depth) {
    const HwNode& n = bvh.nodes[node];
    Aabb box = slot_box(n, slot);
    uint32_t count = n.child_count[slot], ref = n.child_ref[slot];
    // Empty slot: only child 1 of a root whose child 0 is a leaf, with a never-hit box.
    if (count == kEmptyChild) {
        if (node != 0 || slot != 1 || n.child_count[0] == 0)
            fail(node, slot, "empty child outside the root of a one-leaf tree");
        if (!(box.lo.x > box.hi.x && box.lo.y > box.hi.y && box.lo.z > box.hi.z))
            fail(node, slot, "empty child must have an empty box (lo > hi)");
        return;
    }
    if (box.empty() || !parent.contains(box)) fail(node, slot, "box outside its parent's box");
    if (count != 0) return check_leaf(node, slot, box, depth);
    if (ref == 0 || ref >= bvh.nodes.size())
        fail(node, slot, "bad child reference " + std::to_string(ref) + " (" +
                             std::to_string(bvh.nodes.size()) + " nodes)");
    if (node_seen[ref]) fail(node, slot, "node " + std::to_string(ref) + " referenced twice");
    node_seen[ref] = 1;
    stack.push_back(Item{ref, box, depth});
}

void Checker::run() {
    if (bvh.nodes.empty()) throw Error("BVH has no nodes");
    if (spatial_splits ? bvh.triangles.size() < scene.triangles.size() : bvh.triangles.size() != scene.triangles.size())
        throw Error("BVH holds " + std::to_string(bvh.triangles.size()) + " triangles, the scene " +
                    std::to_string(scene.triangles.size()));
    covered.assign(spatial_splits ? scene.triangles.size() : 0, 0.0);
    node_seen.assign(bvh.nodes.size(), 0);
    tri_seen.assign(bvh.triangles.size(), 0);
    prim_seen.assign(scene.triangles.size(), 0);
    if (bvh.nodes[0].child_count[0] == kEmptyChild) fail(0, 0, "root child 0 is empty");

    // Walk from the root; a node's slots must lie inside the box its parent's slot gave it.
    node_seen[0] = 1;
    stack.push_back(Item{0, bvh.bounds, 0});
    while (!stack.empty()) {
        Item item = stack.back();
        stack.pop_back();
        for (int slot = 0; slot < 2; ++slot) check_slot(item.node, slot, item.parent, item.depth + 1);
    }
    for (size_t i = 0; i < node_seen.size(); ++i)
        if (!node_seen[i]) throw Error("BVH node " + std::to_string(i) + " unreachable from the root");
    for (size_t j = 0; j < tri_seen.size(); ++j)
        if (!tri_seen[j]) throw Error("BVH triangle " + std::to_string(j) + " referenced by no leaf");
    for (size_t p = 0; p < prim_seen.size(); ++p)
        if (!prim_seen[p]) throw Error("BVH primitive " + std::to_string(p) + " is in no triangle record");
    // Spatial splits: the leaf boxes of a primitive's records cover all of it (to rounding).
    for (size_t p = 0; p < covered.size(); ++p) {
        const Triangle& s = scene.triangles[p];
        const double whole = ClippedTriangle(s, Aabb{glm::min(glm::min(s.v0, s.v1), s.v2),
                                                     glm::max(glm::max(s.v0, s.v1), s.v2)}).area();
        if (covered[p] < whole * (1.0 - 1e-6))
            throw Error("BVH primitive " + std::to_string(p) + ": its leaf boxes cover " + std::to_string(covered[p]) +
                        " of its area " + std::to_string(whole));
    }
}

}  // namespace

void check_bvh_invariants(const HwBvh& bvh, const Scene& scene, bool spatial_splits) {
    Checker{bvh, scene, spatial_splits, {}, {}, {}, {}, {}}.run();
}

// SAH cost (Goldsmith & Salmon 1987; MacDonald & Booth 1990): every node costs traversal_cost
// and every leaf intersection_cost per triangle, each weighted by its area over the root's.
// A zero-area root (all triangles on one point or line) weighs everything 1.
double sah_cost(const HwBvh& bvh, const BuildConfig& config) {
    return sah_cost(bvh.nodes.data(), bvh.nodes.size(), config);
}

double sah_cost(const HwNode* nodes, size_t count, const BuildConfig& config) {
    auto node_box = [nodes](size_t i) {
        Aabb box;
        for (int slot = 0; slot < 2; ++slot)
            if (nodes[i].child_count[slot] != kEmptyChild) box.grow(slot_box(nodes[i], slot));
        return box;
    };
    if (count == 0) return 0.0;
    // Areas in double: float products overflow for boxes beyond about 1e19.
    auto area = [](const Aabb& box) {
        if (box.empty()) return 0.0;
        glm::dvec3 e = glm::dvec3(box.hi) - glm::dvec3(box.lo);
        return e.x * e.y + e.y * e.z + e.z * e.x;
    };
    double root_area = area(node_box(0));
    auto weight = [root_area, &area](const Aabb& box) {
        return root_area > 0.0 ? area(box) / root_area : 1.0;
    };
    double cost = 0.0;
    for (size_t i = 0; i < count; ++i) {
        const HwNode& node = nodes[i];
        cost += config.traversal_cost * weight(node_box(i));
        for (int slot = 0; slot < 2; ++slot) {
            uint32_t n = node.child_count[slot];
            if (n != 0 && n != kEmptyChild)
                cost += double(config.intersection_cost) * n * weight(slot_box(node, slot));
        }
    }
    return cost;
}

}  // namespace rtsim
