// Invariants of a built kd-tree (kdtree.h), for tests: what the traversal's correctness rests on.
#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "traces/accel/kdtree/kdtree.h"
#include "traces/accel/spatial_params.h"
#include "traces/bvh/build_tree.h"
#include "traces/bvh/sbvh_clip.h"
#include "traces/common/error.h"
#include "traces/scene/scene.h"

namespace rtsim {

namespace {

bool overlaps(const Aabb& a, const Aabb& b) {
    for (int k = 0; k < 3; ++k)
        if (a.lo[k] > b.hi[k] || b.lo[k] > a.hi[k]) return false;
    return true;
}

bool listed(const KdView& v, const KdNode& leaf, uint32_t tri) {
    const uint32_t* first = v.list.refs + leaf.first_ref();
    return std::binary_search(first, first + leaf.ref_count(), tri);
}

}  // namespace

void check_kdtree_invariants(const KdView& v, const Scene& scene) {
    auto fail = [](const std::string& what) { throw Error("kd-tree invariant: " + what); };
    if (v.triangle_count != scene.triangles.size()) fail("triangle records are not the scene's triangles");
    for (uint32_t i = 0; i < v.triangle_count; ++i) {
        const HwTriangle want = make_hw_triangle(scene, i), &got = v.list.triangles[i];
        if (std::memcmp(&want, &got, sizeof want) != 0) fail("triangle record " + std::to_string(i) + " is not the scene's");
    }
    // Every cell, top down; every leaf's list increasing and overlapping its cell.
    std::vector<Aabb> cell(v.node_count);
    cell[0] = v.bounds;
    for (uint64_t i = 0; i < v.node_count; ++i) {
        const KdNode& n = v.nodes[i];
        if (!n.leaf()) {
            cell[i + 1] = cell[n.above()] = cell[i];
            cell[i + 1].hi[n.axis()] = cell[n.above()].lo[n.axis()] = n.split();
            continue;
        }
        const uint32_t* list = v.list.refs + n.first_ref();
        for (uint32_t k = 0; k < n.ref_count(); ++k) {
            if (k && list[k] <= list[k - 1]) fail("leaf " + std::to_string(i) + "'s list is not increasing");
            Aabb box;
            const Triangle& t = scene.triangles[list[k]];
            for (const Vec3& p : {t.v0, t.v1, t.v2}) box.grow(p);
            if (!overlaps(box, cell[i])) fail("leaf " + std::to_string(i) + " lists triangle " + std::to_string(list[k]) + " outside its cell");
        }
    }
    // Every triangle is listed in every leaf where it has area: descend where its clipped part
    // in the cell is not empty (a part of zero area, or a triangle lying in a face of the cell,
    // may be listed on either side).
    for (uint32_t tri = 0; tri < scene.triangles.size(); ++tri) {
        const double whole = ClippedTriangle(scene.triangles[tri], v.bounds).area();
        std::vector<uint64_t> stack{0};
        while (!stack.empty()) {
            const uint64_t i = stack.back();
            stack.pop_back();
            const ClippedTriangle part(scene.triangles[tri], cell[i]);
            if (part.empty() || !(part.area() > 1e-9 * whole) || triangle_in_cell_face(scene.triangles[tri], cell[i])) continue;
            const KdNode& n = v.nodes[i];
            if (n.leaf()) {
                if (!listed(v, n, tri)) fail("triangle " + std::to_string(tri) + " has area in leaf " + std::to_string(i) + " but is not listed");
                continue;
            }
            stack.push_back(i + 1);
            stack.push_back(n.above());
        }
    }
}

}  // namespace rtsim
