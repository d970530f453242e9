// The binary BVH's image, Accel and locality tree (bvh2.h).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "traces/accel/bvh2/bvh2.h"
#include "traces/accel/bvh_image_stats.h"
#include "traces/accel/leaf_coverage.h"
#include "traces/bvh/builder.h"
#include "traces/common/error.h"
#include "traces/isect/brute_force.h"

namespace rtsim {

Bvh2View bvh2_view(const HwBvh& bvh) {
    Bvh2View v;
    v.nodes = bvh.nodes.data();
    v.triangles = bvh.triangles.data();
    v.node_count = bvh.nodes.size();
    v.triangle_count = bvh.triangles.size();
    v.curved = detail::any_curved(bvh.triangles.data(), bvh.triangles.size());
    return v;
}

Hit trace_ray_stepper(const HwBvh& bvh, const Ray& ray, TraversalMode mode, WorkCounts* work) {
    Bvh2Stepper stepper(bvh2_view(bvh));
    return trace_with_stepper(stepper, ray, mode, work);
}

Hit trace_ray_brute_force(const HwBvh& bvh, const Ray& ray, TraversalMode mode) {
    return trace_ray_brute_force(bvh.triangles.data(), bvh.triangles.size(), ray, mode);
}

namespace {

nlohmann::json bvh2_stats(const BvhStats& s, const BuildConfig& c, const std::string& builder) {
    return bvh_image_stats(s, c, builder, 2, sizeof(HwNode));
}

}  // namespace

/// The first triangle of every leaf child, ascending (compressed leaves start a block at each).
/// Leaves own distinct ranges of the `triangles` records, so their starts are marked in a flag
/// per record and collected in order: linear (the sort cost 2% of the Sponza build). (A
/// start out of range or shared by two leaves, which no builder makes, takes the sort.)
std::vector<uint32_t> bvh2_leaf_starts(const Region& nodes, uint64_t triangles) {
    std::vector<uint32_t> starts;
    std::vector<uint8_t> is_start(triangles, 0);
    bool distinct = true;
    const HwNode* n = nodes.records<HwNode>();
    for (uint64_t i = 0; i < nodes.count; ++i)
        for (int c = 0; c < 2; ++c)
            if (n[i].child_count[c] != 0 && n[i].child_count[c] != kEmptyChild) {
                const uint32_t first = n[i].child_ref[c];
                starts.push_back(first);
                if (first >= triangles || is_start[first]) distinct = false;
                else is_start[first] = 1;
            }
    if (!distinct) {
        std::sort(starts.begin(), starts.end());
        return starts;
    }
    size_t k = 0;
    for (uint64_t t = 0; t < triangles; ++t)
        if (is_start[t]) starts[k++] = uint32_t(t);
    return starts;
}

AccelImage bvh2_image(const HwBvh& bvh, const BuildConfig& c, const std::string& builder) {
    AccelImage image;
    image.kind = "bvh2";
    image.bounds = bvh.bounds;
    Region& nodes = image.add_region<HwNode>("nodes", DataKind::node, bvh.nodes.size());
    std::copy(bvh.nodes.begin(), bvh.nodes.end(), nodes.records<HwNode>());
    Region& tris = image.add_region<HwTriangle>("triangles", DataKind::triangle, bvh.triangles.size());
    std::copy(bvh.triangles.begin(), bvh.triangles.end(), tris.records<HwTriangle>());
    image.leaf_starts = bvh2_leaf_starts(image.region("nodes"), image.region("triangles").count);
    image.place_regions();
    image.stats = bvh2_stats(bvh.stats, c, builder);
    return image;
}

AccelImage bvh2_image(const BuildTree& tree, const Scene& scene, const BuildConfig& c, const std::string& builder) {
    AccelImage image;
    image.kind = "bvh2";
    image.bounds = tree.nodes[0].box;
    image.add_region<HwNode>("nodes", DataKind::node, flat_node_count(tree), false);
    image.add_region<HwTriangle>("triangles", DataKind::triangle, tree.prim_ids.size(), false);
    // The regions' records are taken once both exist: adding a region may move the others.
    const BvhStats s = flatten_bvh_into(tree, scene, c, image.region("nodes").records<HwNode>(),
                                        image.region("triangles").records<HwTriangle>());
    image.leaf_starts = bvh2_leaf_starts(image.region("nodes"), image.region("triangles").count);
    image.place_regions();
    image.stats = bvh2_stats(s, c, builder);
    return image;
}

LocalityTree bvh2_locality_tree(const HwNode* nodes, uint64_t count) {
    LocalityTree t;
    std::vector<float> area(count, 0.0f);
    if (count) area[0] = std::numeric_limits<float>::infinity();
    for (uint64_t i = 0; i < count; ++i)
        for (int c = 0; c < 2; ++c)
            if (nodes[i].child_count[c] == 0) {
                const HwNode& n = nodes[i];
                const float ex = n.hi(c, 0) - n.lo(c, 0), ey = n.hi(c, 1) - n.lo(c, 1), ez = n.hi(c, 2) - n.lo(c, 2);
                area[n.child_ref[c]] = ex * ey + ey * ez + ez * ex;
            }
    for (uint64_t i = 0; i < count; ++i) {
        uint64_t bytes = sizeof(HwNode);
        for (int c = 0; c < 2; ++c)
            if (nodes[i].child_count[c] != 0 && nodes[i].child_count[c] != kEmptyChild)
                bytes += uint64_t(nodes[i].child_count[c]) * sizeof(HwTriangle);
        t.add_node(bytes, area[i]);
        for (int c = 0; c < 2; ++c)
            if (nodes[i].child_count[c] == 0) t.add_child(nodes[i].child_ref[c]);
    }
    t.finish();
    return t;
}

namespace {
/// Largest leaf an image may hold (the builders make leaves of at most max_leaf_size <= 64).
constexpr uint32_t kMaxLeafTriangles = 1u << 16;
}  // namespace

void validate_bvh2(const Bvh2View& v, const std::string& source) {
    // Messages are built only on failure: this pass runs over every node of every trace opened.
    auto fail = [&](const std::string& what) { throw Error(source + ": binary BVH: " + what); };
    if (v.node_count == 0) {  // an empty scene: every ray misses
        if (v.triangle_count) fail("no nodes but " + std::to_string(v.triangle_count) + " triangles");
        return;
    }
    auto child = [](uint64_t i, int c) { return "node " + std::to_string(i) + " child " + std::to_string(c); };
    if (v.node_count >= (1ull << 32) || v.triangle_count >= (1ull << 32)) fail("more than 2^32 nodes or triangles");
    // Depth-first layout: a child always comes after its parent, so following children can
    // never cycle, and depth can be checked in one forward pass.
    std::vector<uint8_t> depth(v.node_count, 0), seen(v.node_count, 0);
    LeafCoverage covered(v.triangle_count);
    seen[0] = 1;
    for (uint64_t i = 0; i < v.node_count; ++i) {
        const HwNode& n = v.nodes[i];
        if (!seen[i]) fail("node " + std::to_string(i) + " is not reachable from the root");
        for (int c = 0; c < 2; ++c) {
            const uint32_t ref = n.child_ref[c], count = n.child_count[c];
            if (count == kEmptyChild) {
                // Only the builder's one-leaf root has an empty slot, with a box no ray enters.
                if (i != 0 || c != 1) fail(child(i, c) + " is an empty child slot outside the root");
                if (!(n.lo(c, 0) > n.hi(c, 0) && n.lo(c, 1) > n.hi(c, 1) && n.lo(c, 2) > n.hi(c, 2)))
                    fail(child(i, c) + " is an empty slot with an enterable box");
                continue;
            }
            for (int a = 0; a < 3; ++a)
                if (std::isnan(n.lo(c, a)) || std::isnan(n.hi(c, a))) fail(child(i, c) + " has a NaN in its box");
            if (count == 0) {
                if (ref <= i || ref >= v.node_count)
                    fail(child(i, c) + " points to node " + std::to_string(ref) +
                         (ref < v.node_count ? " (not after its parent)" : " (out of range)"));
                if (seen[ref]) fail("node " + std::to_string(ref) + " has two parents");
                seen[ref] = 1;
                if (depth[i] + 1 >= kTraversalStackSize)
                    fail("deeper than the traversal stack (" + std::to_string(kTraversalStackSize) + ")");
                depth[ref] = uint8_t(depth[i] + 1);
                continue;
            }
            if (count > kMaxLeafTriangles)
                fail(child(i, c) + " is a leaf of " + std::to_string(count) + " triangles (at most " +
                     std::to_string(kMaxLeafTriangles) + ")");
            covered.add(ref, count, fail, [&] { return child(i, c); });
        }
    }
    covered.finish(fail);
}

Bvh2Accel::Bvh2Accel(AccelImage image, const std::string& source) : Accel(std::move(image)) {
    const Region& nodes = m_image.region("nodes");
    const Region& tris = triangle_region(m_image);
    require(nodes.record_bytes == sizeof(HwNode) && triangle_records_ok(tris),
            source + ": bvh2 regions must hold 64-byte nodes and 48-byte triangles");
    m_view.nodes = nodes.records<HwNode>();
    m_view.node_count = nodes.count;
    m_view.node_base = nodes.base;
    m_triangles = TriangleStore::open(m_image, source);
    m_view.triangles = m_triangles.triangles();
    m_view.triangle_count = m_triangles.count();
    m_view.tri_at = m_triangles.addressing();
    m_view.curved = has_curved();
    validate_bvh2(m_view, source);
}

std::unique_ptr<Stepper> Bvh2Accel::make_stepper(const StepOptions& options) const {
    return std::make_unique<Bvh2Stepper>(m_view, options.short_stack_entries, options.box_precision_bits,
                                         options.anyhit_order);
}

Hit Bvh2Accel::trace(const Ray& ray, TraversalMode mode, WorkCounts* work, const StepOptions& options) const {
    if (!options.fused_loop_walks_alike()) return Accel::trace(ray, mode, work, options);
    return trace_bvh2(m_view, ray, mode, work);
}

std::unique_ptr<PacketStepper> Bvh2Accel::make_packet_stepper(const StepOptions& options) const {
    return make_bvh2_packet_stepper(m_view, options.anyhit_order);
}

void Bvh2Accel::trace_packet(const Ray* rays, const TraversalMode* modes, uint32_t n, Hit* hits, WorkCounts* work,
                             PacketCounts* counts, float split_below, const StepOptions& options) const {
    trace_packet_bvh2(m_view, rays, modes, n, hits, work, counts, split_below, options.anyhit_order);
}

LocalityPartition Bvh2Accel::partition(uint64_t budget_bytes) const {
    require(budget_bytes >= sizeof(HwNode), "treelet budget must be at least one node (64 bytes)");
    return partition_tree(bvh2_locality_tree(m_view.nodes, m_view.node_count), budget_bytes);
}

std::vector<OpKind> Bvh2Accel::op_kinds() const {
    return with_record_kinds({OpKind::box, OpKind::triangle});
}

}  // namespace rtsim
