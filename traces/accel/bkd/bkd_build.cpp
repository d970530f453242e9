// Building a B-Kd tree (bkd.h): a binary BVH build tree's children turned into intervals on one
// axis per node, and the image with its statistics.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "traces/accel/bkd/bkd.h"
#include "traces/accel/spatial_params.h"
#include "traces/common/error.h"
#include "traces/scene/scene.h"

namespace rtsim {
namespace bkd_detail {

double half_area(const Aabb& b) {
    const double x = double(b.hi.x) - b.lo.x, y = double(b.hi.y) - b.lo.y, z = double(b.hi.z) - b.lo.z;
    return std::max(0.0, x * y + y * z + z * x);
}

/// `cell` cut to [lo, hi] on `axis`.
Aabb cut(Aabb cell, int axis, float lo, float hi) {
    cell.lo[axis] = std::max(cell.lo[axis], lo);
    cell.hi[axis] = std::min(cell.hi[axis], hi);
    return cell;
}

}  // namespace bkd_detail

BkdTree bkd_from_build_tree(const BuildTree& tree) {
    require(tree.nodes.size() <= BkdNode::kMaxIndex && tree.prim_ids.size() <= BkdNode::kMaxIndex,
            "bkd: more than 2^30 nodes or triangles");
    BkdTree t;
    t.prim_ids = tree.prim_ids;
    t.bounds = tree.nodes[0].box;
    t.nodes.resize(tree.nodes.size());
    // References under every node (children come after their parents: one backwards pass).
    std::vector<double> refs(tree.nodes.size(), 0.0);
    for (size_t i = tree.nodes.size(); i-- > 0;) {
        const BuildNode& n = tree.nodes[i];
        refs[i] = n.is_leaf() ? double(n.count) : refs[n.first] + refs[n.first + 1];
    }
    // Top down: each build node goes to the slot of its pair its side takes; its cell is its
    // parent's cut by its interval. The axis: the cheapest pair of cells by the SAH (Woop et al.
    // 2006 keep the BVH's tree and choose per node the axis that bounds the children best).
    std::vector<uint32_t> slot(tree.nodes.size(), 0);
    std::vector<Aabb> cell(tree.nodes.size());
    cell[0] = t.bounds;
    for (size_t i = 0; i < tree.nodes.size(); ++i) {
        const BuildNode& n = tree.nodes[i];
        if (n.is_leaf()) {
            t.nodes[slot[i]] = BkdNode::make_leaf(n.first, n.count);
            continue;
        }
        const Aabb& b0 = tree.nodes[n.first].box;
        const Aabb& b1 = tree.nodes[n.first + 1].box;
        double best = std::numeric_limits<double>::infinity();
        int axis = 0;
        for (int a = 0; a < 3; ++a) {
            const double cost = bkd_detail::half_area(bkd_detail::cut(cell[i], a, b0.lo[a], b0.hi[a])) * refs[n.first] +
                                bkd_detail::half_area(bkd_detail::cut(cell[i], a, b1.lo[a], b1.hi[a])) * refs[n.first + 1];
            if (cost < best) best = cost, axis = a;
        }
        // The child lower on the axis first: the stepper's near child for rays running up it.
        const bool swapped = b1.lo[axis] + b1.hi[axis] < b0.lo[axis] + b0.hi[axis];
        const uint32_t l = n.first + (swapped ? 1 : 0), r = n.first + (swapped ? 0 : 1);
        const Aabb &lb = tree.nodes[l].box, &rb = tree.nodes[r].box;
        t.nodes[slot[i]] = BkdNode::interior(axis, n.first, lb.lo[axis], lb.hi[axis], rb.lo[axis], rb.hi[axis]);
        slot[l] = n.first;
        slot[r] = n.first + 1;
        cell[l] = bkd_detail::cut(cell[i], axis, lb.lo[axis], lb.hi[axis]);
        cell[r] = bkd_detail::cut(cell[i], axis, rb.lo[axis], rb.hi[axis]);
    }
    return t;
}

AccelImage bkd_image(const BkdTree& tree, const Scene& scene, const std::string& builder) {
    AccelImage image;
    image.kind = "bkd";
    image.bounds = tree.bounds;
    image.params = root_cell_json(tree.bounds);
    Region& nodes = image.add_region<BkdNode>("nodes", DataKind::node, tree.nodes.size());
    std::copy(tree.nodes.begin(), tree.nodes.end(), nodes.records<BkdNode>());
    Region& tris = image.add_region<HwTriangle>("triangles", DataKind::triangle, tree.prim_ids.size());
    const HwTriangleWriter write(scene);
    write.write(tree.prim_ids.data(), tree.prim_ids.size(), tris.records<HwTriangle>());
    for (const BkdNode& n : tree.nodes)
        if (n.leaf() && n.count()) image.leaf_starts.push_back(n.first());
    image.place_regions();
    // Statistics over the cells, top down (SAH with C_t = C_i = 1, as the BVHs report it).
    std::vector<Aabb> cell(tree.nodes.size());
    std::vector<uint32_t> depth(tree.nodes.size(), 0);
    cell[0] = tree.bounds;
    const double root = std::max(bkd_detail::half_area(tree.bounds), 1e-300);
    double sah = 0.0;
    uint64_t leaves = 0, max_leaf = 0, deepest = 0;
    for (size_t i = 0; i < tree.nodes.size(); ++i) {
        const BkdNode& n = tree.nodes[i];
        deepest = std::max<uint64_t>(deepest, depth[i]);
        if (n.leaf()) {
            sah += bkd_detail::half_area(cell[i]) / root * n.count();
            leaves += 1;
            max_leaf = std::max<uint64_t>(max_leaf, n.count());
            continue;
        }
        sah += bkd_detail::half_area(cell[i]) / root;
        for (int side = 0; side < 2; ++side) {
            cell[n.left() + side] = bkd_detail::cut(cell[i], n.axis(), n.bound(side, 0), n.bound(side, 1));
            depth[n.left() + side] = depth[i] + 1;
        }
    }
    image.stats = {{"builder", builder},
                   {"width", 2},
                   {"node_bytes", sizeof(BkdNode)},
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
