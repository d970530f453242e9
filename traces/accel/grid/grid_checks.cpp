// The uniform grid's layout invariants and its locality partition into bricks (grid.h).
#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "traces/accel/grid/grid.h"
#include "traces/bvh/build_tree.h"
#include "traces/common/error.h"
#include "traces/scene/scene.h"

namespace rtsim {

void check_grid_invariants(const GridView& v, const Scene& scene) {
    auto fail = [](const std::string& what) { throw Error("grid: " + what); };
    const GridGeometry& g = v.geometry;
    if (v.triangle_count != scene.triangles.size())
        fail("holds " + std::to_string(v.triangle_count) + " triangles, the scene " +
             std::to_string(scene.triangles.size()));
    // Each triangle's cell range: the cells its box overlaps.
    std::vector<uint32_t> range(6 * v.triangle_count);
    uint64_t expected = 0;
    for (uint64_t i = 0; i < v.triangle_count; ++i) {
        const HwTriangle want = make_hw_triangle(scene, uint32_t(i));
        if (std::memcmp(&want, &v.list.triangles[i], sizeof(HwTriangle)) != 0)
            fail("triangle " + std::to_string(i) + " differs from the scene's primitive " + std::to_string(i));
        const Triangle& t = scene.triangles[i];
        Aabb box;
        box.grow(t.v0), box.grow(t.v1), box.grow(t.v2);
        uint64_t cells = 1;
        for (int a = 0; a < 3; ++a) {
            uint32_t* r = &range[6 * i + 2 * a];
            if (box.lo[a] < g.plane(a, 0) || box.hi[a] > g.plane(a, g.res[a]) ||
                !g.slab_range(a, box.lo[a], box.hi[a], &r[0], &r[1]))
                fail("triangle " + std::to_string(i) + " is not inside the grid's bounds");
            cells *= r[1] - r[0] + 1;
        }
        expected += cells;
    }
    // Lists contiguous in cell order, strictly increasing, each entry's box overlapping its cell.
    uint64_t next = 0;
    for (uint32_t z = 0; z < g.res[2]; ++z)
        for (uint32_t y = 0; y < g.res[1]; ++y)
            for (uint32_t x = 0; x < g.res[0]; ++x) {
                const uint32_t c = g.cell_index(x, y, z);
                const GridCell& cell = v.cells[c];
                if (cell.first_ref != next) fail("cell " + std::to_string(c) + "'s list does not follow the previous one");
                next += cell.ref_count;
                if (next > v.ref_count) fail("cell " + std::to_string(c) + "'s list runs past prim_refs");
                const uint32_t xyz[3] = {x, y, z};
                for (uint32_t k = 0; k < cell.ref_count; ++k) {
                    const uint32_t t = v.list.refs[cell.first_ref + k];
                    if (k > 0 && t <= v.list.refs[cell.first_ref + k - 1])
                        fail("cell " + std::to_string(c) + "'s list is not in increasing triangle order");
                    if (t >= v.triangle_count) fail("cell " + std::to_string(c) + " lists a triangle out of range");
                    for (int a = 0; a < 3; ++a)
                        if (xyz[a] < range[6 * t + 2 * a] || xyz[a] > range[6 * t + 2 * a + 1])
                            fail("cell " + std::to_string(c) + " lists triangle " + std::to_string(t) +
                                 ", whose box does not overlap it");
                }
            }
    // Every listed pair is valid and unique, so equal totals mean none is missing.
    if (next != v.ref_count || expected != v.ref_count)
        fail(std::to_string(v.ref_count) + " references, but the triangles' boxes overlap " +
             std::to_string(expected) + " cells (a triangle is missing from a cell its box overlaps)");
}

namespace {

/// Bytes a cell brings to its brick: itself, its list and one triangle per entry.
uint64_t cell_bytes(const GridCell& c) { return sizeof(GridCell) + uint64_t(c.ref_count) * (kRefBytes + sizeof(HwTriangle)); }

/// Per-brick bytes for bricks of b^3 cells (x fastest over bricks).
std::vector<uint64_t> brick_bytes(const GridView& v, uint32_t b, uint32_t dims[3]) {
    const GridGeometry& g = v.geometry;
    for (int a = 0; a < 3; ++a) dims[a] = (g.res[a] + b - 1) / b;
    std::vector<uint64_t> bytes(uint64_t(dims[0]) * dims[1] * dims[2], 0);
    for (uint32_t z = 0; z < g.res[2]; ++z)
        for (uint32_t y = 0; y < g.res[1]; ++y)
            for (uint32_t x = 0; x < g.res[0]; ++x)
                bytes[x / b + dims[0] * (y / b + dims[1] * (z / b))] += cell_bytes(v.cells[g.cell_index(x, y, z)]);
    return bytes;
}

}  // namespace

LocalityPartition grid_partition(const GridView& v, uint64_t budget) {
    require(budget >= sizeof(GridCell), "brick budget must be at least one cell (8 bytes)");
    const GridGeometry& g = v.geometry;
    const uint32_t largest = std::max(g.res[0], std::max(g.res[1], g.res[2]));
    // The largest power-of-two brick whose every brick fits (bricks of one cell always do).
    uint32_t b = 1, dims[3];
    for (uint32_t next = 2; next / 2 < largest; next *= 2) {
        const std::vector<uint64_t> bytes = brick_bytes(v, next, dims);
        if (*std::max_element(bytes.begin(), bytes.end()) > budget) break;
        b = next;
    }
    const std::vector<uint64_t> bytes = brick_bytes(v, b, dims);
    LocalityPartition p;
    p.budget_bytes = budget;
    p.group_of.resize(v.cell_count);
    p.treelets.resize(bytes.size());
    for (size_t i = 0; i < bytes.size(); ++i) p.treelets[i].bytes = bytes[i];
    for (uint32_t z = 0; z < g.res[2]; ++z)
        for (uint32_t y = 0; y < g.res[1]; ++y)
            for (uint32_t x = 0; x < g.res[0]; ++x) {
                const uint32_t brick = x / b + dims[0] * (y / b + dims[1] * (z / b)), c = g.cell_index(x, y, z);
                p.group_of[c] = brick;
                TreeletInfo& t = p.treelets[brick];
                if (t.nodes++ == 0) t.root = c;  // the brick's lowest corner cell comes first
            }
    p.root_group = 0;  // rays start with the bounds test, which has no key
    return p;
}

}  // namespace rtsim
