#pragma once
// The invariants the binary cell trees share (BIH, B-Kd: a child's cell is its parent's cut on
// the node's axis), checked by their check_*_invariants: the triangle records are the scene's,
// each once, and every leaf's triangles lie in its cell.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "traces/common/aabb.h"
#include "traces/common/hw_triangle.h"
#include "traces/scene/scene.h"

namespace rtsim {

/// `cut(node, parent_cell, left_cell, right_cell)` gives an interior node's children's cells;
/// `fail(message)` throws.
template <class Node, class Cut, class Fail>
void check_cell_tree_invariants(const Node* nodes, uint64_t node_count, const HwTriangle* triangles,
                                uint64_t triangle_count, const Aabb& bounds, const Scene& scene,
                                const Cut& cut, const Fail& fail) {
    std::vector<uint8_t> seen(scene.triangles.size(), 0);
    for (uint64_t k = 0; k < triangle_count; ++k) {
        const uint32_t prim = triangles[k].prim;
        if (prim >= seen.size() || seen[prim]++) fail("triangle records are not a permutation of the scene's");
        const HwTriangle want = make_hw_triangle(scene, prim);
        if (std::memcmp(&want, &triangles[k], sizeof want) != 0) fail("record " + std::to_string(k) + " is not the scene's");
    }
    std::vector<Aabb> cell(node_count);
    cell[0] = bounds;
    for (uint64_t i = 0; i < node_count; ++i) {
        const Node& n = nodes[i];
        if (n.leaf()) {
            for (uint32_t k = n.first(); k < n.first() + n.count(); ++k) {
                Aabb box;
                const HwTriangle& t = triangles[k];
                for (const float* p : {t.v0, t.v1, t.v2}) box.grow(Vec3(p[0], p[1], p[2]));
                if (!cell[i].contains(box)) fail("triangle record " + std::to_string(k) + " lies outside the cell of leaf " + std::to_string(i));
            }
            continue;
        }
        cut(n, cell[i], cell[n.left()], cell[n.left() + 1]);
    }
}

}  // namespace rtsim
