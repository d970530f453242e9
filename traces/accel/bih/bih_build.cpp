// Building a BIH (bih.h): Wachter & Keller's global heuristic, or a binary BVH build tree's
// children turned into clip planes; and the image with its statistics.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "traces/accel/bih/bih.h"
#include "traces/accel/spatial_params.h"
#include "traces/common/error.h"
#include "traces/scene/scene.h"

namespace rtsim {
namespace {

struct Item {
    uint32_t node, first, count, depth;
    Aabb split;  ///< the split box: the space this node's plane candidates halve
};

double half_area(const Aabb& b) {
    const double x = double(b.hi.x) - b.lo.x, y = double(b.hi.y) - b.lo.y, z = double(b.hi.z) - b.lo.z;
    return std::max(0.0, x * y + y * z + z * x);
}

/// The split plane of Wachter & Keller 2006 (section 2.2, the global heuristic): the middle of
/// the split box's longest axis; a side left empty halves the other side's box and tries again,
/// so the planes stay those of a regular subdivision of the root. Returns the left count and the
/// children's split boxes, or `count` (no split found: every centre coincides, or the box cannot
/// be halved any more).
uint32_t global_heuristic(std::vector<uint32_t>& ids, const std::vector<Vec3>& centre, const Item& item, int* axis,
                          Aabb* left_split, Aabb* right_split) {
    uint32_t* begin = ids.data() + item.first;
    Aabb split = item.split;
    for (int attempt = 0; attempt < 256; ++attempt) {
        const int a = split.largest_axis();
        const float lo = split.lo[a], hi = split.hi[a], plane = lo + (hi - lo) * 0.5f;
        if (!(plane > lo && plane < hi)) break;
        const uint32_t left =
            uint32_t(std::partition(begin, begin + item.count, [&](uint32_t i) { return centre[i][a] <= plane; }) - begin);
        if (left == 0) {
            split.lo[a] = plane;
        } else if (left == item.count) {
            split.hi[a] = plane;
        } else {
            *axis = a;
            *left_split = *right_split = split;
            left_split->hi[a] = right_split->lo[a] = plane;
            return left;
        }
    }
    return item.count;
}

}  // namespace

BihTree build_bih(const Scene& scene, const BihConfig& c) {
    const size_t n = scene.triangles.size();
    require(n > 0, "bih: the scene has no triangles");
    require(n <= BihNode::kMaxIndex, "bih: too many triangles (>= 2^30)");
    require(c.max_leaf_size >= 1 && c.max_depth >= 16 && c.max_depth <= kBihMaxDepth,
            "BihConfig: max_leaf_size must be >= 1 and max_depth in 16.." + std::to_string(kBihMaxDepth));
    require(median_levels_needed(uint32_t(n), c.max_leaf_size) < c.max_depth, "bih: max_depth too small for the scene");
    std::vector<Aabb> box(n);
    std::vector<Vec3> centre(n);
    BihTree t;
    for (size_t i = 0; i < n; ++i) {
        for (const Vec3& v : {scene.triangles[i].v0, scene.triangles[i].v1, scene.triangles[i].v2}) {
            require(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z),
                    "bih: triangle " + std::to_string(i) + " has a non-finite vertex");
            box[i].grow(v);
        }
        centre[i] = box[i].center();
        t.bounds.grow(box[i]);
    }
    t.prim_ids.resize(n);
    std::iota(t.prim_ids.begin(), t.prim_ids.end(), 0u);
    t.nodes.push_back(BihNode{});
    std::vector<Item> stack{{0, 0, uint32_t(n), 0, t.bounds}};
    while (!stack.empty()) {
        Item item = stack.back();
        stack.pop_back();
        if (item.count <= c.max_leaf_size) {
            t.nodes[item.node] = BihNode::make_leaf(item.first, item.count);
            continue;
        }
        int axis = 0;
        uint32_t left = item.count;
        Aabb left_split = item.split, right_split = item.split;
        // Near max_depth the range is halved at its median so every leaf still fits.
        if (item.depth + 1 + median_levels_needed(item.count, c.max_leaf_size) < c.max_depth)
            left = global_heuristic(t.prim_ids, centre, item, &axis, &left_split, &right_split);
        if (left == item.count) {  // the object median on the centres' widest axis
            Aabb cb;
            for (uint32_t k = item.first; k < item.first + item.count; ++k) cb.grow(centre[t.prim_ids[k]]);
            axis = cb.largest_axis();
            left = item.count / 2;
            uint32_t* b = t.prim_ids.data() + item.first;
            std::nth_element(b, b + left, b + item.count, [&](uint32_t x, uint32_t y) {
                return centre[x][axis] < centre[y][axis] || (centre[x][axis] == centre[y][axis] && x < y);
            });
        }
        // Clip planes: the left objects' highest extent and the right objects' lowest on the axis.
        float clip0 = -std::numeric_limits<float>::infinity(), clip1 = std::numeric_limits<float>::infinity();
        for (uint32_t k = item.first; k < item.first + left; ++k) clip0 = std::max(clip0, box[t.prim_ids[k]].hi[axis]);
        for (uint32_t k = item.first + left; k < item.first + item.count; ++k)
            clip1 = std::min(clip1, box[t.prim_ids[k]].lo[axis]);
        const uint32_t child = uint32_t(t.nodes.size());
        require(child + 1 <= BihNode::kMaxIndex, "bih: more than 2^30 nodes");
        t.nodes.push_back(BihNode{});
        t.nodes.push_back(BihNode{});
        t.nodes[item.node] = BihNode::interior(axis, child, clip0, clip1);
        stack.push_back({child + 1, item.first + left, item.count - left, item.depth + 1, right_split});
        stack.push_back({child, item.first, left, item.depth + 1, left_split});
    }
    return t;
}

BihTree bih_from_build_tree(const BuildTree& tree) {
    BihTree t;
    t.prim_ids = tree.prim_ids;
    t.bounds = tree.nodes[0].box;
    t.nodes.resize(tree.nodes.size());
    // References under every node (children come after their parents: one backwards pass).
    std::vector<double> refs(tree.nodes.size(), 0.0);
    for (size_t i = tree.nodes.size(); i-- > 0;) {
        const BuildNode& n = tree.nodes[i];
        refs[i] = n.is_leaf() ? double(n.count) : refs[n.first] + refs[n.first + 1];
    }
    // Top down: each build node goes to the slot of its pair that its chosen side takes; its cell
    // is its parent's cut by its clip plane.
    std::vector<uint32_t> slot(tree.nodes.size(), 0);
    std::vector<Aabb> cell(tree.nodes.size());
    cell[0] = t.bounds;
    for (size_t i = 0; i < tree.nodes.size(); ++i) {
        const BuildNode& n = tree.nodes[i];
        if (n.is_leaf()) {
            t.nodes[slot[i]] = BihNode::make_leaf(n.first, n.count);
            continue;
        }
        double best = std::numeric_limits<double>::infinity();
        int best_axis = 0;
        bool swapped = false;
        for (int a = 0; a < 3; ++a)
            for (bool swap : {false, true}) {
                const uint32_t l = n.first + (swap ? 1 : 0), r = n.first + (swap ? 0 : 1);
                Aabb lc = cell[i], rc = cell[i];
                lc.hi[a] = std::min(lc.hi[a], tree.nodes[l].box.hi[a]);
                rc.lo[a] = std::max(rc.lo[a], tree.nodes[r].box.lo[a]);
                const double cost = half_area(lc) * refs[l] + half_area(rc) * refs[r];
                if (cost < best) best = cost, best_axis = a, swapped = swap;
            }
        const uint32_t l = n.first + (swapped ? 1 : 0), r = n.first + (swapped ? 0 : 1);
        const float clip0 = tree.nodes[l].box.hi[best_axis], clip1 = tree.nodes[r].box.lo[best_axis];
        t.nodes[slot[i]] = BihNode::interior(best_axis, n.first, clip0, clip1);
        slot[l] = n.first;
        slot[r] = n.first + 1;
        cell[l] = cell[r] = cell[i];
        cell[l].hi[best_axis] = std::min(cell[i].hi[best_axis], clip0);
        cell[r].lo[best_axis] = std::max(cell[i].lo[best_axis], clip1);
    }
    return t;
}

AccelImage bih_image(const BihTree& tree, const Scene& scene, const std::string& builder) {
    AccelImage image;
    image.kind = "bih";
    image.bounds = tree.bounds;
    image.params = root_cell_json(tree.bounds);
    Region& nodes = image.add_region<BihNode>("nodes", DataKind::node, tree.nodes.size());
    std::copy(tree.nodes.begin(), tree.nodes.end(), nodes.records<BihNode>());
    Region& tris = image.add_region<HwTriangle>("triangles", DataKind::triangle, tree.prim_ids.size());
    for (size_t k = 0; k < tree.prim_ids.size(); ++k) tris.records<HwTriangle>()[k] = make_hw_triangle(scene, tree.prim_ids[k]);
    for (const BihNode& n : tree.nodes)
        if (n.leaf() && n.count()) image.leaf_starts.push_back(n.first());
    image.place_regions();
    // Statistics over the cells, top down (SAH with C_t = C_i = 1, as the BVHs report it).
    std::vector<Aabb> cell(tree.nodes.size());
    std::vector<uint32_t> depth(tree.nodes.size(), 0);
    cell[0] = tree.bounds;
    const double root = std::max(half_area(tree.bounds), 1e-300);
    double sah = 0.0;
    uint64_t leaves = 0, max_leaf = 0, deepest = 0;
    for (size_t i = 0; i < tree.nodes.size(); ++i) {
        const BihNode& n = tree.nodes[i];
        deepest = std::max<uint64_t>(deepest, depth[i]);
        if (n.leaf()) {
            sah += half_area(cell[i]) / root * n.count();
            leaves += 1;
            max_leaf = std::max<uint64_t>(max_leaf, n.count());
            continue;
        }
        sah += half_area(cell[i]) / root;
        const uint32_t l = n.left(), r = l + 1;
        cell[l] = cell[r] = cell[i];
        cell[l].hi[n.axis()] = std::min(cell[i].hi[n.axis()], n.clip(0));
        cell[r].lo[n.axis()] = std::max(cell[i].lo[n.axis()], n.clip(1));
        depth[l] = depth[r] = depth[i] + 1;
    }
    image.stats = {{"builder", builder},
                   {"width", 2},
                   {"node_bytes", sizeof(BihNode)},
                   {"triangle_bytes", sizeof(HwTriangle)},
                   {"nodes", tree.nodes.size()},
                   {"leaves", leaves},
                   {"max_depth", deepest},
                   {"avg_leaf_size", leaves ? double(tree.prim_ids.size()) / double(leaves) : 0.0},
                   {"max_leaf_size", max_leaf},
                   {"sah_cost", sah}};
    return image;
}

}  // namespace rtsim
