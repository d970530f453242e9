// Building the fp32 wide images (wide.h): wide tree, node and triangle order (WideOrder), records.
#include <algorithm>

#include "traces/accel/bvh_image_stats.h"
#include "traces/accel/wide/wide.h"
#include "traces/common/error.h"

namespace rtsim {

const char* child_order_name(ChildOrder order) { return order == ChildOrder::octant ? "octant" : "distance"; }

ChildOrder child_order_param(const AccelImage& image, const std::string& source) {
    const auto it = image.params.find("order");
    if (it == image.params.end()) return ChildOrder::distance;
    if (it->is_string() && *it == "distance") return ChildOrder::distance;
    if (it->is_string() && *it == "octant") return ChildOrder::octant;
    throw Error(source + ": " + image.kind + ": params.order must be \"distance\" or \"octant\"");
}

WideBuildTree make_wide_tree(const BuildTree& tree, const Scene& scene, int width, const BuildConfig& config,
                             ChildOrder order, Collapse method) {
    return make_wide_tree(BuildTree(tree), scene, width, config, order, method);
}

WideBuildTree make_wide_tree(BuildTree&& tree, const Scene& scene, int width, const BuildConfig& config,
                             ChildOrder order, Collapse method) {
    CollapseConfig c;
    c.width = width;
    c.leaf_max = std::max(1u, std::min(kWideLeafMax, config.max_leaf_size));
    c.method = method;
    c.traversal_cost = config.traversal_cost;
    c.intersection_cost = config.intersection_cost;
    WideBuildTree wide = collapse_tree(split_large_leaves(std::move(tree), scene.triangles, c.leaf_max), c);
    if (order == ChildOrder::octant) assign_octant_slots(wide);
    return wide;
}

namespace {

template <int N>
void write_fp32_nodes(const WideBuildTree& tree, const WideOrder& order, WideNode<N>* out) {
    for (size_t i = 0; i < order.stored.size(); ++i) {
        const uint32_t b = order.stored[i];
        const WideBuildNode& n = tree.nodes[b];
        WideNode<N>& w = out[i];
        for (int s = 0; s < N; ++s) {  // every slot empty until a child takes it
            for (int a = 0; a < 3; ++a) {
                w.lo(s, a) = std::numeric_limits<float>::infinity();
                w.hi(s, a) = -std::numeric_limits<float>::infinity();
            }
            w.child_ref[s] = 0;
            w.child_count[s] = kEmptyChild;
        }
        for (uint32_t k = 0; k < n.count; ++k) {
            const WideBuildChild& c = n.child[k];
            const int s = n.slot[k];
            for (int a = 0; a < 3; ++a) {
                w.lo(s, a) = c.box.lo[a];
                w.hi(s, a) = c.box.hi[a];
            }
            w.child_ref[s] = c.is_leaf() ? order.leaf_first[size_t(b) * kMaxWideWidth + k] : order.index[c.node];
            w.child_count[s] = c.count;
        }
    }
}

/// The "nodes" region of N-wide fp32 nodes, written.
template <int N>
void add_fp32_nodes(const WideBuildTree& tree, const WideOrder& o, AccelImage& image) {
    Region& nodes = image.add_region<WideNode<N>>("nodes", DataKind::node, o.stored.size());
    write_fp32_nodes<N>(tree, o, nodes.records<WideNode<N>>());
}

}  // namespace

AccelImage wide_image(const WideBuildTree& tree, const Scene& scene, const std::string& kind, ChildOrder order) {
    const WideOrder o = wide_order(tree);
    AccelImage image;
    image.kind = kind;
    image.bounds = tree.nodes[0].box;
    image.params = {{"order", child_order_name(order)}};
    switch (tree.width) {
        case 4: add_fp32_nodes<4>(tree, o, image); break;
        case 6: add_fp32_nodes<6>(tree, o, image); break;
        case 8: add_fp32_nodes<8>(tree, o, image); break;
        default: throw Error("wide_image: no fp32 layout of width " + std::to_string(tree.width));
    }
    Region& tris = image.add_region<HwTriangle>("triangles", DataKind::triangle, o.prims.size());
    HwTriangle* t = tris.records<HwTriangle>();
    HwTriangleWriter(scene).write(o.prims.data(), o.prims.size(), t);
    image.leaf_starts = o.leaf_starts;
    image.place_regions();
    return image;
}

nlohmann::json wide_stats(const WideBuildTree& tree, const BuildConfig& c, const std::string& builder,
                          uint32_t node_bytes, ChildOrder order) {
    const WideShape s = wide_shape(tree);
    BvhStats b;
    b.nodes = uint32_t(tree.nodes.size());
    b.leaves = s.leaves;
    b.max_depth = s.max_depth;
    b.avg_leaf_size = s.avg_leaf_size;
    b.max_leaf_size = s.max_leaf_size;
    b.sah_cost = wide_sah_cost(tree, c.traversal_cost, c.intersection_cost);
    nlohmann::json j = bvh_image_stats(b, c, builder, tree.width, node_bytes);
    j.update(nlohmann::json{{"avg_children", s.avg_children},
              {"triangle_refs", tree.prims.size()},
              {"collapse", "dp"},
              {"order", child_order_name(order)}});
    return j;
}

std::unique_ptr<Accel> load_wide_fp32(AccelImage image, int width, const std::string& source) {
    switch (width) {
        case 4: return std::make_unique<WideAccel<Fp32Codec<4>>>(std::move(image), source);
        case 6: return std::make_unique<WideAccel<Fp32Codec<6>>>(std::move(image), source);
        case 8: return std::make_unique<WideAccel<Fp32Codec<8>>>(std::move(image), source);
        default: throw Error(source + ": no fp32 wide layout of width " + std::to_string(width));
    }
}

}  // namespace rtsim
