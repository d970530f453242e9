// The B-Kd tree's validation, Accel, locality tree and invariants (bkd.h).
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "traces/accel/bkd/bkd.h"
#include "traces/accel/bkd/bkd_packet.h"
#include "traces/accel/cell_tree_invariants.h"
#include "traces/accel/leaf_coverage.h"
#include "traces/accel/spatial_params.h"
#include "traces/common/error.h"
#include "traces/scene/scene.h"

namespace rtsim {

namespace bkd_detail {

/// Child `side`'s cell: its parent's cut to the child's interval on the node's axis.
Aabb child_cell(Aabb cell, const BkdNode& n, int side) {
    cell.lo[n.axis()] = std::max(cell.lo[n.axis()], n.bound(side, 0));
    cell.hi[n.axis()] = std::min(cell.hi[n.axis()], n.bound(side, 1));
    return cell;
}

}  // namespace bkd_detail

using bkd_detail::child_cell;

uint32_t validate_bkd(const BkdView& v, const std::string& source) {
    // Messages are built only on failure: this pass runs over every node of every trace opened.
    auto fail = [&](const std::string& what) { throw Error(source + ": B-Kd tree: " + what); };
    auto node_name = [](uint64_t i) { return "node " + std::to_string(i); };
    if (v.node_count == 0) fail("no nodes");
    if (v.node_count > BkdNode::kMaxIndex || v.triangle_count > BkdNode::kMaxIndex)
        fail("more than 2^30 nodes or triangles");
    std::vector<uint8_t> depth(v.node_count, 0), seen(v.node_count, 0);
    LeafCoverage covered(v.triangle_count);
    seen[0] = 1;
    uint32_t deepest = 0;
    for (uint64_t i = 0; i < v.node_count; ++i) {
        const BkdNode& n = v.nodes[i];
        if (!seen[i]) fail(node_name(i) + " is not reachable from the root");
        deepest = std::max<uint32_t>(deepest, depth[i]);
        if (n.leaf()) {
            covered.add(n.first(), n.count(), fail, [&] { return node_name(i); });
            continue;
        }
        for (int p = 0; p < 4; ++p)
            if (std::isnan(n.bound(p / 2, p % 2))) fail(node_name(i) + " has a NaN plane");
        for (uint64_t k : {uint64_t(n.left()), uint64_t(n.left()) + 1}) {
            if (k <= i || k >= v.node_count)
                fail(node_name(i) + " names child " + std::to_string(k) + (k < v.node_count ? " (not after it)" : " (out of range)"));
            if (seen[k]) fail(node_name(k) + " has two parents");
            if (depth[i] + 1u >= kBkdMaxDepth) fail("deeper than the traversal stack (" + std::to_string(kBkdMaxDepth) + ")");
            seen[k] = 1;
            depth[k] = uint8_t(depth[i] + 1);
        }
    }
    covered.finish(fail);
    return deepest;
}

void check_bkd_invariants(const BkdView& v, const Scene& scene) {
    auto fail = [](const std::string& what) { throw Error("B-Kd invariant: " + what); };
    // A child's cell: the parent's cut to the child's interval.
    auto cut = [](const BkdNode& n, const Aabb& parent, Aabb& left, Aabb& right) {
        left = child_cell(parent, n, 0);
        right = child_cell(parent, n, 1);
    };
    check_cell_tree_invariants(v.nodes, v.node_count, v.triangles, v.triangle_count, v.bounds, scene, cut, fail);
}

BkdAccel::BkdAccel(AccelImage image, const std::string& source) : Accel(std::move(image)) {
    const Region& nodes = m_image.region("nodes");
    const Region& tris = triangle_region(m_image);
    require(nodes.record_bytes == sizeof(BkdNode) && triangle_records_ok(tris),
            source + ": bkd regions must hold 20-byte nodes and 48-byte triangles");
    require(nodes.kind == DataKind::node && tris.kind == DataKind::triangle,
            source + ": bkd regions must be of data kinds node and triangle");
    m_view.nodes = nodes.records<BkdNode>();
    m_view.node_count = nodes.count;
    m_view.node_base = nodes.base;
    m_triangles = TriangleStore::open(m_image, source);
    m_view.triangles = m_triangles.triangles();
    m_view.triangle_count = m_triangles.count();
    m_view.tri_at = m_triangles.addressing();
    m_view.curved = has_curved();
    m_view.bounds = root_cell_from_json(m_image.params, source + ": bkd params");
    m_depth = validate_bkd(m_view, source);
}

std::unique_ptr<Stepper> BkdAccel::make_stepper(const StepOptions&) const { return std::make_unique<BkdStepper>(m_view); }

std::unique_ptr<PacketStepper> BkdAccel::make_packet_stepper(const StepOptions&) const {
    return std::make_unique<CellPacketStepper<detail::BkdPacketRules>>(detail::BkdPacketRules{{m_view}}, 0);
}

Hit BkdAccel::trace(const Ray& ray, TraversalMode mode, WorkCounts* work, const StepOptions&) const {
    BkdStepper stepper(m_view);  // on the stack: no allocation, no virtual calls
    return trace_with_stepper(stepper, ray, mode, work);
}

LocalityPartition BkdAccel::partition(uint64_t budget_bytes) const {
    require(budget_bytes >= sizeof(BkdNode), "treelet budget must be at least one node (20 bytes)");
    LocalityTree t;
    std::vector<Aabb> cell(m_view.node_count);
    cell[0] = m_view.bounds;
    for (uint64_t i = 0; i < m_view.node_count; ++i) {
        const BkdNode& n = m_view.nodes[i];
        t.add_node(sizeof(BkdNode) + (n.leaf() ? uint64_t(n.count()) * sizeof(HwTriangle) : 0),
                   i == 0 ? std::numeric_limits<float>::infinity() : cell[i].half_area());
        if (n.leaf()) continue;
        const uint32_t l = n.left();
        for (int side = 0; side < 2; ++side) cell[l + side] = child_cell(cell[i], n, side);
        t.add_child(l);
        t.add_child(l + 1);
    }
    t.finish();
    return partition_tree(t, budget_bytes);
}

std::vector<OpKind> BkdAccel::op_kinds() const {
    return with_record_kinds({OpKind::box, OpKind::plane, OpKind::triangle});
}

}  // namespace rtsim
