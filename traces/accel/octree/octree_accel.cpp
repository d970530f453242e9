// The octree's validation, Accel, locality tree and invariants (octree.h).
#include <algorithm>
#include <cmath>
#include <limits>
#include <cstring>
#include <string>
#include <vector>

#include "traces/accel/octree/octree.h"
#include "traces/accel/octree/octree_packet.h"
#include "traces/accel/spatial_params.h"
#include "traces/bvh/build_tree.h"
#include "traces/bvh/sbvh_clip.h"
#include "traces/common/error.h"
#include "traces/scene/scene.h"

namespace rtsim {

namespace {

/// Every node's cell, top down (children after parents).
std::vector<Aabb> octree_cells(const OctView& v) {
    std::vector<Aabb> cell(v.node_count);
    cell[0] = v.bounds;
    for (uint64_t i = 0; i < v.node_count; ++i) {
        const OctNode& n = v.nodes[i];
        if (n.leaf()) continue;
        const float centre[3] = {n.centre(0), n.centre(1), n.centre(2)};
        for (uint32_t c = 0; c < 8; ++c)
            if (n.mask() >> c & 1u) cell[n.child(c)] = octree_child_cell(cell[i], centre, c);
    }
    return cell;
}

}  // namespace

uint32_t validate_octree(const OctView& v, const std::string& source) {
    // The centre must lie inside the cell; each stored child's cell is an octant of it.
    const ListedChecks check(source, "octree");
    return validate_listed_tree(
        v, check, kOctMaxDepth, [] { return "deeper than " + std::to_string(kOctMaxDepth) + " levels"; },
        [&](uint64_t i, const OctNode& n, const Aabb& cell, auto&& add_child) {
            const float centre[3] = {n.centre(0), n.centre(1), n.centre(2)};
            for (int a = 0; a < 3; ++a)
                if (!(centre[a] >= cell.lo[a] && centre[a] <= cell.hi[a]))
                    check.fail("node " + std::to_string(i) + "'s centre is outside its cell on axis " +
                               std::to_string(a));
            for (uint32_t c = 0; c < 8; ++c)
                if (n.mask() >> c & 1u) add_child(n.child(c), octree_child_cell(cell, centre, c));
        });
}

void check_octree_invariants(const OctView& v, const Scene& scene) {
    auto fail = [](const std::string& what) { throw Error("octree invariant: " + what); };
    if (v.triangle_count != scene.triangles.size()) fail("triangle records are not the scene's triangles");
    for (uint32_t i = 0; i < v.triangle_count; ++i) {
        const HwTriangle want = make_hw_triangle(scene, i);
        if (std::memcmp(&want, &v.list.triangles[i], sizeof want) != 0) fail("record " + std::to_string(i) + " is not the scene's");
    }
    const std::vector<Aabb> cell = octree_cells(v);
    for (uint64_t i = 0; i < v.node_count; ++i) {
        const OctNode& n = v.nodes[i];
        if (!n.leaf()) continue;
        const uint32_t* list = v.list.refs + n.first_ref();
        for (uint32_t k = 1; k < n.ref_count(); ++k)
            if (list[k] <= list[k - 1]) fail("leaf " + std::to_string(i) + "'s list is not increasing");
    }
    // A triangle with area in a cell is listed by the cell's leaf, or the cell has a stored child
    // for every part of it (empty children hold no triangle with area).
    for (uint32_t tri = 0; tri < scene.triangles.size(); ++tri) {
        const double whole = ClippedTriangle(scene.triangles[tri], v.bounds).area();
        std::vector<uint64_t> stack{0};
        while (!stack.empty()) {
            const uint64_t i = stack.back();
            stack.pop_back();
            const ClippedTriangle part(scene.triangles[tri], cell[i]);
            if (part.empty() || !(part.area() > 1e-9 * whole) || triangle_in_cell_face(scene.triangles[tri], cell[i]))
                continue;
            const OctNode& n = v.nodes[i];
            if (n.leaf()) {
                const uint32_t* first = v.list.refs + n.first_ref();
                if (!std::binary_search(first, first + n.ref_count(), tri))
                    fail("triangle " + std::to_string(tri) + " has area in leaf " + std::to_string(i) + " but is not listed");
                continue;
            }
            const float centre[3] = {n.centre(0), n.centre(1), n.centre(2)};
            for (uint32_t c = 0; c < 8; ++c) {
                if (n.mask() >> c & 1u) {
                    stack.push_back(n.child(c));
                    continue;
                }
                bool uncut = false;  // the upper side of an axis that is not cut is no cell
                for (int a = 0; a < 3; ++a) uncut = uncut || ((c >> a & 1u) && centre[a] == cell[i].hi[a]);
                if (uncut) continue;
                const Aabb child = octree_child_cell(cell[i], centre, c);
                const ClippedTriangle missing(scene.triangles[tri], child);
                if (!missing.empty() && missing.area() > 1e-9 * whole && !triangle_in_cell_face(scene.triangles[tri], child))
                    fail("triangle " + std::to_string(tri) + " has area in empty child " + std::to_string(c) + " of node " + std::to_string(i));
            }
        }
    }
}

OctreeAccel::OctreeAccel(AccelImage image, const std::string& source) : Accel(std::move(image)) {
    m_view = open_listed_tree<OctNode>(m_image, m_triangles, "octree", source);
    m_depth = validate_octree(m_view, source);
}

std::unique_ptr<Stepper> OctreeAccel::make_stepper(const StepOptions& options) const {
    return std::make_unique<OctreeStepper>(m_view, options.mailbox_entries);
}

std::unique_ptr<PacketStepper> OctreeAccel::make_packet_stepper(const StepOptions& options) const {
    return std::make_unique<CellPacketStepper<detail::OctreePacketRules>>(detail::OctreePacketRules{m_view},
                                                                          options.mailbox_entries);
}

Hit OctreeAccel::trace(const Ray& ray, TraversalMode mode, WorkCounts* work, const StepOptions& options) const {
    OctreeStepper stepper(m_view, options.mailbox_entries);  // on the stack: no allocation, no virtual calls
    return trace_with_stepper(stepper, ray, mode, work);
}

LocalityPartition OctreeAccel::partition(uint64_t budget_bytes) const {
    require(budget_bytes >= sizeof(OctNode), "treelet budget must be at least one node (16 bytes)");
    const std::vector<Aabb> cell = octree_cells(m_view);
    LocalityTree t;
    for (uint64_t i = 0; i < m_view.node_count; ++i) {
        const OctNode& n = m_view.nodes[i];
        uint64_t bytes = sizeof(OctNode);
        if (n.leaf()) bytes += uint64_t(n.ref_count()) * (kRefBytes + sizeof(HwTriangle));
        t.add_node(bytes, i == 0 ? std::numeric_limits<float>::infinity() : cell[i].half_area());
        for (uint32_t c = 0; c < 8; ++c)
            if (!n.leaf() && (n.mask() >> c & 1u)) t.add_child(n.child(c));
    }
    t.finish();
    return partition_tree(t, budget_bytes);
}

std::vector<OpKind> OctreeAccel::op_kinds() const {
    return with_record_kinds({OpKind::box, OpKind::plane, OpKind::triangle});
}

}  // namespace rtsim
