// Flattening of the build tree into the hardware layout (hw_layout.h, docs/bvh_layout.md), and
// build_bvh(), the entry point that times the whole build.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "traces/bvh/build_tree.h"
#include "traces/bvh/builder.h"
#include "traces/common/error.h"

namespace rtsim {
namespace {

void set_slot_box(HwNode& node, int slot, const Aabb& box) {
    for (int a = 0; a < 3; ++a) {
        node.lo(slot, a) = box.lo[a];
        node.hi(slot, a) = box.hi[a];
    }
}

/// An unused slot: empty box (lo = +inf, hi = -inf) that no ray can hit.
void set_empty_slot(HwNode& node, int slot) {
    set_slot_box(node, slot, Aabb{});
    node.child_ref[slot] = 0;
    node.child_count[slot] = kEmptyChild;
}

/// A build node whose HwNode is still to be written, and the parent slot that will point to it.
struct Pending {
    uint32_t build;
    uint32_t parent;  // HwNode index, or kNoParent for the root
    uint32_t slot;
    uint32_t depth;
};
constexpr uint32_t kNoParent = std::numeric_limits<uint32_t>::max();

/// The flags word of material `index` (kTriAnyHit, coverage, material), or an error naming the
/// triangle if the index is not one the scene or the layout holds.
uint32_t material_flags(const Scene& scene, uint32_t material, uint32_t prim) {
    if (material >= scene.materials.size() || material >= (1u << 16))
        throw Error("build_bvh: triangle " + std::to_string(prim) + " has material index " + std::to_string(material) +
                    " (scene has " + std::to_string(scene.materials.size()) + ", the layout holds up to 65536)");
    const Material& m = scene.materials[material];
    float coverage = std::min(1.0f, std::max(0.0f, m.alpha_coverage));
    uint32_t coverage8 = uint32_t(std::lround(coverage * 255.0f));
    return (m.alpha_mode == AlphaMode::mask ? kTriAnyHit : 0u) | (coverage8 << kTriCoverageShift) |
           (material << kTriMaterialShift);
}

HwTriangle triangle_record(const Scene& scene, uint32_t prim, uint32_t flags) {
    const Triangle& t = scene.triangles[prim];
    HwTriangle hw;
    if (scene.is_capsule(prim)) {  // docs/bvh_layout.md, "Capsule records"
        const Vec3 &a = scene.capsule_ends[prim][0], &b = scene.capsule_ends[prim][1];
        return HwTriangle{{a.x, a.y, a.z}, {b.x, b.y, b.z}, {scene.curved_radius[prim], scene.end_radius(prim), 0.0f}, prim,
                          scene.tri_instance[prim], flags | kPrimCapsule};
    }
    if (scene.is_sphere(prim)) {  // docs/bvh_layout.md, "Sphere records"
        const Vec3 c = sphere_centre(t);
        hw = HwTriangle{{c.x, c.y, c.z}, {scene.curved_radius[prim], 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f}, prim,
                        scene.tri_instance[prim], flags | kPrimSphere};
        return hw;
    }
    for (int a = 0; a < 3; ++a) {
        hw.v0[a] = t.v0[a];
        hw.v1[a] = t.v1[a];
        hw.v2[a] = t.v2[a];
    }
    hw.prim = prim;
    hw.inst = scene.tri_instance[prim];
    hw.flags = flags;
    return hw;
}

}  // namespace

HwTriangle make_hw_triangle(const Scene& scene, uint32_t prim) {
    return triangle_record(scene, prim, material_flags(scene, scene.tri_material[prim], prim));
}

HwTriangleWriter::HwTriangleWriter(const Scene& scene) : m_scene(scene) {
    m_flags.resize(std::min<size_t>(scene.materials.size(), size_t(1) << 16));
    for (uint32_t m = 0; m < m_flags.size(); ++m) m_flags[m] = material_flags(scene, m, 0);
}

HwTriangle HwTriangleWriter::operator()(uint32_t prim) const {
    const uint32_t material = m_scene.tri_material[prim];
    if (material >= m_flags.size()) material_flags(m_scene, material, prim);  // throws, naming the triangle
    return triangle_record(m_scene, prim, m_flags[material]);
}

void HwTriangleWriter::write(const uint32_t* prims, size_t count, HwTriangle* out) const {
    // Primitives come in leaf order, scattered over the scene's arrays: the reads of a record a
    // few ahead are started early, or each record waits for three cache misses.
    constexpr size_t kAhead = 8;
    for (size_t i = 0; i < count; ++i) {
        if (i + kAhead < count) {
            const uint32_t p = prims[i + kAhead];
            __builtin_prefetch(&m_scene.triangles[p]);
            __builtin_prefetch(&m_scene.tri_material[p]);
            __builtin_prefetch(&m_scene.tri_instance[p]);
        }
        out[i] = (*this)(prims[i]);
    }
}

size_t flat_node_count(const BuildTree& tree) { return tree.nodes[0].is_leaf() ? 1 : (tree.nodes.size() - 1) / 2; }

BvhStats flatten_bvh_into(const BuildTree& tree, const Scene& scene, const BuildConfig& config, HwNode* nodes,
                          HwTriangle* triangles) {
    const BuildNode& root = tree.nodes[0];
    // Triangles in leaf order: build leaves own prim_ids ranges in left-before-right order,
    // which is also the depth-first order below, so leaf references keep their build offsets.
    HwTriangleWriter(scene).write(tree.prim_ids.data(), tree.prim_ids.size(), triangles);

    BvhStats stats;
    auto note_leaf = [&stats](uint32_t count, uint32_t depth) {
        ++stats.leaves;
        stats.max_leaf_size = std::max(stats.max_leaf_size, count);
        stats.max_depth = std::max(stats.max_depth, depth);
    };

    // A root that is a leaf still gets an interior HwNode: child 0 the leaf, child 1 empty.
    size_t count = 0;
    if (root.is_leaf()) {
        HwNode& node = nodes[count++];
        set_slot_box(node, 0, root.box);
        node.child_ref[0] = root.first;
        node.child_count[0] = root.count;
        set_empty_slot(node, 1);
        note_leaf(root.count, 1);
    } else {
        // Depth-first, left child right after its parent (pbrt-v4's flattenBVH order).
        std::vector<Pending> stack;
        stack.reserve(2 * size_t(config.max_depth) + 2);
        stack.push_back(Pending{0, kNoParent, 0, 0});
        while (!stack.empty()) {
            Pending p = stack.back();
            stack.pop_back();
            const uint32_t index = uint32_t(count++);
            if (p.parent != kNoParent) nodes[p.parent].child_ref[p.slot] = index;
            HwNode& node = nodes[index];
            const BuildNode& b = tree.nodes[p.build];
            for (uint32_t slot = 0; slot < 2; ++slot) {
                const BuildNode& child = tree.nodes[b.first + slot];
                set_slot_box(node, int(slot), child.box);
                node.child_ref[slot] = child.is_leaf() ? child.first : 0;
                node.child_count[slot] = child.is_leaf() ? child.count : 0;
                if (child.is_leaf()) note_leaf(child.count, p.depth + 1);
            }
            // Push right then left so the left child is emitted next.
            for (int slot = 1; slot >= 0; --slot)
                if (!tree.nodes[b.first + slot].is_leaf())
                    stack.push_back(Pending{b.first + slot, index, uint32_t(slot), p.depth + 1});
        }
    }
    stats.nodes = uint32_t(count);
    stats.avg_leaf_size = double(tree.prim_ids.size()) / double(stats.leaves);
    stats.sah_cost = sah_cost(nodes, count, config);
    return stats;
}

HwBvh flatten_bvh(const BuildTree& tree, const Scene& scene, const BuildConfig& config) {
    HwBvh out;
    out.bounds = tree.nodes[0].box;
    out.nodes.resize(flat_node_count(tree));
    out.triangles.resize(tree.prim_ids.size());
    out.stats = flatten_bvh_into(tree, scene, config, out.nodes.data(), out.triangles.data());
    return out;
}

HwBvh build_bvh(const Scene& scene, const BuildConfig& config) {
    auto start = std::chrono::steady_clock::now();
    require(!scene.triangles.empty(), "scene has no triangles");
    require(scene.tri_material.size() == scene.triangles.size() &&
                scene.tri_instance.size() == scene.triangles.size(),
            "build_bvh: scene is not flattened (tri_material/tri_instance sizes differ from "
            "triangles; call Scene::flatten())");
    BuildTree tree = build_binned_sah(scene.triangles, config);
    HwBvh bvh = flatten_bvh(tree, scene, config);
    auto stop = std::chrono::steady_clock::now();
    bvh.stats.build_ms = std::chrono::duration<double, std::milli>(stop - start).count();
    return bvh;
}

}  // namespace rtsim
