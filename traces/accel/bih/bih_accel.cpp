// The BIH's validation, Accel, locality tree and invariants (bih.h).
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "traces/accel/bih/bih.h"
#include "traces/accel/bih/bih_packet.h"
#include "traces/accel/cell_tree_invariants.h"
#include "traces/accel/leaf_coverage.h"
#include "traces/accel/spatial_params.h"
#include "traces/common/error.h"
#include "traces/scene/scene.h"

namespace rtsim {

uint32_t validate_bih(const BihView& v, const std::string& source) {
    // Messages are built only on failure: this pass runs over every node of every trace opened.
    auto fail = [&](const std::string& what) { throw Error(source + ": BIH: " + what); };
    auto node_name = [](uint64_t i) { return "node " + std::to_string(i); };
    if (v.node_count == 0) fail("no nodes");
    if (v.node_count > BihNode::kMaxIndex || v.triangle_count > BihNode::kMaxIndex)
        fail("more than 2^30 nodes or triangles");
    std::vector<uint8_t> depth(v.node_count, 0), seen(v.node_count, 0);
    LeafCoverage covered(v.triangle_count);
    seen[0] = 1;
    uint32_t deepest = 0;
    for (uint64_t i = 0; i < v.node_count; ++i) {
        const BihNode& n = v.nodes[i];
        if (!seen[i]) fail(node_name(i) + " is not reachable from the root");
        deepest = std::max<uint32_t>(deepest, depth[i]);
        if (n.leaf()) {
            // word2 is reserved in a leaf: 0 in every image the builder makes.
            if (n.word2 != 0) fail(node_name(i) + " is a leaf with a non-zero reserved word (word2 = " + std::to_string(n.word2) + ")");
            covered.add(n.first(), n.count(), fail, [&] { return node_name(i); });
            continue;
        }
        if (std::isnan(n.clip(0)) || std::isnan(n.clip(1))) fail(node_name(i) + " has a NaN clip plane");
        for (uint64_t k : {uint64_t(n.left()), uint64_t(n.left()) + 1}) {
            if (k <= i || k >= v.node_count)
                fail(node_name(i) + " names child " + std::to_string(k) + (k < v.node_count ? " (not after it)" : " (out of range)"));
            if (seen[k]) fail(node_name(k) + " has two parents");
            if (depth[i] + 1u >= kBihMaxDepth) fail("deeper than the traversal stack (" + std::to_string(kBihMaxDepth) + ")");
            seen[k] = 1;
            depth[k] = uint8_t(depth[i] + 1);
        }
    }
    covered.finish(fail);
    return deepest;
}

void check_bih_invariants(const BihView& v, const Scene& scene) {
    auto fail = [](const std::string& what) { throw Error("BIH invariant: " + what); };
    // A child's cell: the parent's cut at its clip plane.
    auto cut = [](const BihNode& n, const Aabb& parent, Aabb& left, Aabb& right) {
        left = right = parent;
        left.hi[n.axis()] = std::min(parent.hi[n.axis()], n.clip(0));
        right.lo[n.axis()] = std::max(parent.lo[n.axis()], n.clip(1));
    };
    check_cell_tree_invariants(v.nodes, v.node_count, v.triangles, v.triangle_count, v.bounds, scene, cut, fail);
}

BihAccel::BihAccel(AccelImage image, const std::string& source) : Accel(std::move(image)) {
    const Region& nodes = m_image.region("nodes");
    const Region& tris = triangle_region(m_image);
    require(nodes.record_bytes == sizeof(BihNode) && triangle_records_ok(tris),
            source + ": bih regions must hold 12-byte nodes and 48-byte triangles");
    require(nodes.kind == DataKind::node && tris.kind == DataKind::triangle,
            source + ": bih regions must be of data kinds node and triangle");
    m_view.nodes = nodes.records<BihNode>();
    m_view.node_count = nodes.count;
    m_view.node_base = nodes.base;
    m_triangles = TriangleStore::open(m_image, source);
    m_view.triangles = m_triangles.triangles();
    m_view.triangle_count = m_triangles.count();
    m_view.tri_at = m_triangles.addressing();
    m_view.curved = has_curved();
    m_view.bounds = root_cell_from_json(m_image.params, source + ": bih params");
    m_depth = validate_bih(m_view, source);
}

std::unique_ptr<Stepper> BihAccel::make_stepper(const StepOptions& options) const {
    return std::make_unique<BihStepper>(m_view, options.short_stack_entries);
}

std::unique_ptr<PacketStepper> BihAccel::make_packet_stepper(const StepOptions&) const {
    return std::make_unique<CellPacketStepper<detail::BihPacketRules>>(detail::BihPacketRules{{m_view}}, 0);
}

Hit BihAccel::trace(const Ray& ray, TraversalMode mode, WorkCounts* work, const StepOptions& options) const {
    BihStepper stepper(m_view, options.short_stack_entries);  // on the stack: no allocation, no virtual calls
    return trace_with_stepper(stepper, ray, mode, work);
}

LocalityPartition BihAccel::partition(uint64_t budget_bytes) const {
    require(budget_bytes >= sizeof(BihNode), "treelet budget must be at least one node (12 bytes)");
    LocalityTree t;
    std::vector<Aabb> cell(m_view.node_count);
    cell[0] = m_view.bounds;
    for (uint64_t i = 0; i < m_view.node_count; ++i) {
        const BihNode& n = m_view.nodes[i];
        t.add_node(sizeof(BihNode) + (n.leaf() ? uint64_t(n.count()) * sizeof(HwTriangle) : 0),
                   i == 0 ? std::numeric_limits<float>::infinity() : cell[i].half_area());
        if (n.leaf()) continue;
        const uint32_t l = n.left();
        cell[l] = cell[l + 1] = cell[i];
        cell[l].hi[n.axis()] = std::min(cell[i].hi[n.axis()], n.clip(0));
        cell[l + 1].lo[n.axis()] = std::max(cell[i].lo[n.axis()], n.clip(1));
        t.add_child(l);
        t.add_child(l + 1);
    }
    t.finish();
    return partition_tree(t, budget_bytes);
}

std::vector<OpKind> BihAccel::op_kinds() const {
    return with_record_kinds({OpKind::box, OpKind::plane, OpKind::triangle});
}

}  // namespace rtsim
