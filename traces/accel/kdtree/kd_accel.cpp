// The kd-tree's image, validation, Accel and locality tree (kdtree.h).
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "traces/accel/kdtree/kdtree.h"
#include "traces/accel/kdtree/kd_packet.h"
#include "traces/accel/spatial_params.h"
#include "traces/bvh/build_tree.h"
#include "traces/common/error.h"
#include "traces/scene/scene.h"

namespace rtsim {

AccelImage kdtree_image(const Scene& scene, const KdConfig& config) {
    KdTreeBuild kd = build_kdtree(scene, config);
    AccelImage image;
    image.kind = "kdtree";
    image.bounds = kd.bounds;
    image.params = root_cell_json(kd.bounds);
    Region& nodes = image.add_region<KdNode>("nodes", DataKind::node, kd.nodes.size());
    std::copy(kd.nodes.begin(), kd.nodes.end(), nodes.records<KdNode>());
    Region& refs = image.add_region<uint32_t>("prim_refs", DataKind::prim_ref, kd.refs.size());
    std::copy(kd.refs.begin(), kd.refs.end(), refs.records<uint32_t>());
    const size_t n = scene.triangles.size();
    HwTriangle* tris = image.add_region<HwTriangle>("triangles", DataKind::triangle, n).records<HwTriangle>();
    for (size_t i = 0; i < n; ++i) tris[i] = make_hw_triangle(scene, uint32_t(i));
    image.place_regions();
    image.stats = std::move(kd.stats);
    return image;
}

uint32_t validate_kdtree(const KdView& v, const std::string& source) {
    // Depth first: a node's below child is the next node; the split must lie inside the cell.
    const ListedChecks check(source, "kd-tree");
    return validate_listed_tree(
        v, check, kKdMaxDepth - 1, [] { return "deeper than the traversal stack (" + std::to_string(kKdMaxDepth) + ")"; },
        [&](uint64_t i, const KdNode& n, const Aabb& cell, auto&& add_child) {
            const int a = n.axis();
            const float p = n.split();
            if (!(std::isfinite(p) && p >= cell.lo[a] && p <= cell.hi[a]))
                check.fail("node " + std::to_string(i) + " splits axis " + std::to_string(a) + " at " +
                           std::to_string(p) + " outside its cell");
            Aabb below = cell, above = cell;
            below.hi[a] = p;
            above.lo[a] = p;
            add_child(i + 1, below);
            add_child(n.above(), above);
        });
}

KdAccel::KdAccel(AccelImage image, const std::string& source) : Accel(std::move(image)) {
    m_view = open_listed_tree<KdNode>(m_image, m_triangles, "kdtree", source);
    m_depth = validate_kdtree(m_view, source);
}

std::unique_ptr<Stepper> KdAccel::make_stepper(const StepOptions& options) const {
    return std::make_unique<KdStepper>(m_view, options.mailbox_entries, options.short_stack_entries);
}

std::unique_ptr<PacketStepper> KdAccel::make_packet_stepper(const StepOptions& options) const {
    return std::make_unique<CellPacketStepper<detail::KdPacketRules>>(detail::KdPacketRules{m_view},
                                                                      options.mailbox_entries);
}

Hit KdAccel::trace(const Ray& ray, TraversalMode mode, WorkCounts* work, const StepOptions& options) const {
    KdStepper stepper(m_view, options.mailbox_entries, options.short_stack_entries);  // on the stack: no allocation, no virtual calls
    return trace_with_stepper(stepper, ray, mode, work);
}

LocalityPartition KdAccel::partition(uint64_t budget_bytes) const {
    require(budget_bytes >= sizeof(KdNode), "treelet budget must be at least one node (8 bytes)");
    // A node brings itself and, for a leaf, its list and one triangle per reference; its
    // probability is its cell's surface area.
    LocalityTree t;
    std::vector<Aabb> cell(m_view.node_count);
    cell[0] = m_view.bounds;
    for (uint64_t i = 0; i < m_view.node_count; ++i) {
        const KdNode& n = m_view.nodes[i];
        uint64_t bytes = sizeof(KdNode);
        if (n.leaf()) bytes += uint64_t(n.ref_count()) * (kRefBytes + sizeof(HwTriangle));
        t.add_node(bytes, i == 0 ? std::numeric_limits<float>::infinity() : cell[i].half_area());
        if (n.leaf()) continue;
        cell[i + 1] = cell[n.above()] = cell[i];
        cell[i + 1].hi[n.axis()] = cell[n.above()].lo[n.axis()] = n.split();
        t.add_child(uint32_t(i + 1));
        t.add_child(n.above());
    }
    t.finish();
    return partition_tree(t, budget_bytes);
}

std::vector<OpKind> KdAccel::op_kinds() const {
    return with_record_kinds({OpKind::box, OpKind::plane, OpKind::triangle});
}

}  // namespace rtsim
