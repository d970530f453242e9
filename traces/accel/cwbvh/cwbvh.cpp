// Building and loading the compressed wide BVHs (cwbvh.h).
#include "traces/accel/cwbvh/cwbvh.h"

#include <type_traits>

#include "traces/common/error.h"

namespace rtsim {
namespace {

void set_bases(CwNode8& n, uint32_t node, uint32_t tri) {
    n.base_node = node;
    n.base_tri = tri;
}
void set_bases(CwNode6& n, uint32_t node, uint32_t tri) { n.set_bases(node, tri); }

/// One compressed node from build node b: frame, bases, meta, outward-quantised child boxes.
template <class Node, int W>
void write_node(const WideBuildTree& tree, const WideOrder& o, uint32_t b, Node& out) {
    const WideBuildNode& n = tree.nodes[b];
    out = Node{};
    const QuantFrame f = make_quant_frame(n.box);
    for (int a = 0; a < 3; ++a) {
        out.p[a] = f.p[a];
        out.e[a] = f.e[a];
    }
    // Children in slot order: interior ones are stored consecutively from the first, leaves'
    // triangles consecutively from the first leaf's (wide_order).
    int child_at[W];
    std::fill(child_at, child_at + W, -1);
    for (uint32_t k = 0; k < n.count; ++k) child_at[n.slot[k]] = int(k);
    uint32_t base_node = 0, base_tri = 0;
    bool have_node = false, have_tri = false;
    for (int s = 0; s < W; ++s) {
        if (child_at[s] < 0) continue;
        const WideBuildChild& c = n.child[child_at[s]];
        if (!c.is_leaf() && !have_node) base_node = o.index[c.node], have_node = true;
        if (c.is_leaf() && !have_tri) base_tri = o.leaf_first[size_t(b) * kMaxWideWidth + uint32_t(child_at[s])], have_tri = true;
    }
    set_bases(out, base_node, base_tri);
    // The children's bounds, slot by slot, quantised an axis at a time.
    int slot_of[W];
    uint32_t used = 0;
    float lo[3][W], hi[3][W];
    for (int s = 0; s < W; ++s) {
        if (child_at[s] < 0) continue;
        const WideBuildChild& c = n.child[child_at[s]];
        for (int a = 0; a < 3; ++a) lo[a][used] = c.box.lo[a], hi[a][used] = c.box.hi[a];
        slot_of[used++] = s;
    }
    for (int a = 0; a < 3; ++a) {
        uint8_t q_lo[W], q_hi[W];
        quantize_bounds(f, a, lo[a], hi[a], used, q_lo, q_hi);
        for (uint32_t k = 0; k < used; ++k) out.qlo[a][slot_of[k]] = q_lo[k], out.qhi[a][slot_of[k]] = q_hi[k];
    }
    for (int s = 0; s < W; ++s) {
        if (child_at[s] < 0) continue;
        const WideBuildChild& c = n.child[child_at[s]];
        if (c.is_leaf()) {
            if (c.count > kWideLeafMax)
                throw Error("cwbvh: leaf of " + std::to_string(c.count) + " triangles (at most 3)");
            const uint32_t offset = o.leaf_first[size_t(b) * kMaxWideWidth + uint32_t(child_at[s])] - base_tri;
            out.meta[s] = meta_leaf(c.count, offset);
        } else {
            out.meta[s] = meta_interior(s);
            if constexpr (std::is_same_v<Node, CwNode8>) out.imask |= uint8_t(1u << s);
        }
    }
}

/// Half the surface area of decoded slot s, in double.
double slot_area(const DecodedNode& d, int s) {
    const double x = double(d.hi[0][s]) - d.lo[0][s], y = double(d.hi[1][s]) - d.lo[1][s],
                 z = double(d.hi[2][s]) - d.lo[2][s];
    return x * y + y * z + z * x;
}

template <class Codec>
double sah_of_nodes(const Region& nodes, const Aabb& root, float ct, float ci) {
    const glm::dvec3 e = glm::dvec3(root.hi) - glm::dvec3(root.lo);
    const double root_area = e.x * e.y + e.y * e.z + e.z * e.x;
    auto weight = [&](double a) { return root_area > 0.0 ? a / root_area : 1.0; };
    double cost = nodes.count ? double(ct) : 0.0;  // the root, always visited
    DecodedNode d;
    for (uint64_t i = 0; i < nodes.count; ++i) {
        Codec::decode(nodes.records<typename Codec::Node>()[i], d);
        for (int s = 0; s < Codec::kWidth; ++s)
            if (d.valid >> s & 1u)
                cost += (d.count[s] ? double(ci) * d.count[s] : double(ct)) * weight(slot_area(d, s));
    }
    return cost;
}

}  // namespace

double cwbvh_sah_cost(const AccelImage& image, float traversal_cost, float intersection_cost) {
    const Region& nodes = image.region("nodes");
    if (nodes.record_bytes == sizeof(CwNode8))
        return sah_of_nodes<Cw8Codec>(nodes, image.bounds, traversal_cost, intersection_cost);
    return sah_of_nodes<Cw6Codec>(nodes, image.bounds, traversal_cost, intersection_cost);
}

AccelImage cwbvh_image(const WideBuildTree& tree, const Scene& scene, const std::string& kind, ChildOrder order) {
    require(tree.width == 8 || tree.width == 6, "cwbvh: no compressed layout of width " + std::to_string(tree.width));
    const WideOrder o = wide_order(tree);
    if (tree.width == 6)
        require(o.stored.size() < CwNode6::kIndexLimit && o.prims.size() < CwNode6::kIndexLimit,
                "cwbvh6: more than 2^28 nodes or triangles (the node's 28-bit bases cannot address them)");
    AccelImage image;
    image.kind = kind;
    image.bounds = tree.nodes[0].box;
    image.params = {{"order", child_order_name(order)}};
    Region& nodes = tree.width == 8 ? image.add_region<CwNode8>("nodes", DataKind::node, o.stored.size())
                                    : image.add_region<CwNode6>("nodes", DataKind::node, o.stored.size());
    for (size_t i = 0; i < o.stored.size(); ++i) {
        if (tree.width == 8) write_node<CwNode8, 8>(tree, o, o.stored[i], nodes.records<CwNode8>()[i]);
        else write_node<CwNode6, 6>(tree, o, o.stored[i], nodes.records<CwNode6>()[i]);
    }
    Region& tris = image.add_region<HwTriangle>("triangles", DataKind::triangle, o.prims.size());
    HwTriangle* t = tris.records<HwTriangle>();
    HwTriangleWriter(scene).write(o.prims.data(), o.prims.size(), t);
    image.leaf_starts = o.leaf_starts;
    image.place_regions();
    return image;
}

std::unique_ptr<Accel> load_cwbvh(AccelImage image, int width, const std::string& source) {
    if (width == 8) return std::make_unique<WideAccel<Cw8Codec>>(std::move(image), source);
    if (width == 6) return std::make_unique<WideAccel<Cw6Codec>>(std::move(image), source);
    throw Error(source + ": no compressed layout of width " + std::to_string(width));
}

}  // namespace rtsim
