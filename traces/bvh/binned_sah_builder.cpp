// Binned SAH builder (Wald 2007, "On fast construction of SAH-based bounding volume
// hierarchies"), written in the manner of madmann91/bvh v2's binned_sah_builder.h: primitives
// become compact 32-byte references that are binned by centroid and partitioned in place, so a
// node costs two linear passes over its range and nothing is allocated per node.
//
// What makes it fast without changing a single split (every tree is bit for bit the one the
// plain algorithm builds, tested against its hashes; docs/bvh_layout.md, "Builder"): most nodes
// are small (on Sponza half the nodes split hold two references, 80% at most eight), so the
// per-node work matters more than the per-reference work. The SAH sweeps visit only the filled
// bins ("groups"): a boundary after an empty bin prices exactly the split of the boundary before
// it, which the strict "<" already preferred. Small nodes find their groups by ranking instead
// of binning, pairs directly (binned_sah_groups.cpp); large ones bin two halves at once and reset
// only the bins they filled.
#include <algorithm>
#include <cmath>
#include <string>

#include "traces/bvh/binned_sah_impl.h"
#include "traces/common/error.h"

namespace rtsim {
namespace binned_detail {
namespace {

/// Equals kTraversalStackSize (traces/isect/traversal.h): deeper trees could overflow it.
constexpr uint32_t kMaxSupportedDepth = 64;

}  // namespace

namespace {

/// Three floats into lanes 0..2, lane 3 zero.
inline Float4 load3(const Vec3& v) { return Float4{v[0], v[1], v[2], 0.0f}; }

/// True if every lane is finite (inf - inf and NaN - NaN are NaN, which compares unequal).
inline bool all_finite(Float4 v) {
    const Int4 ok = (v - v) == Float4{0.0f, 0.0f, 0.0f, 0.0f};
    return (ok[0] & ok[1] & ok[2]) != 0;
}

}  // namespace

// Per-primitive boxes, rejecting non-finite vertices (docs/architecture.md, rule 11), in one
// pass that also grows the root's box and its centroid bounds (in reference order, as a pass
// over the references would). Lane for lane the box is std::min(v0, std::min(v1, v2)) and
// std::max(v0, std::max(v1, v2)): vmin(a, b) = a < b ? a : b is std::min(b, a).
RootBoxes make_refs(const std::vector<Triangle>& triangles, PrimRefs& refs) {
    refs.resize(triangles.size());
    RootBoxes root;
    for (size_t i = 0; i < triangles.size(); ++i) {
        const Triangle& t = triangles[i];
        const Float4 v0 = load3(t.v0), v1 = load3(t.v1), v2 = load3(t.v2);
        if (!all_finite(v0) || !all_finite(v1) || !all_finite(v2))
            throw Error("build_bvh: triangle " + std::to_string(i) + " has a non-finite vertex");
        PrimRef& r = refs[i];
        r.lo = vmin(vmin(v2, v1), v0);
        r.hi = vmax(vmax(v2, v1), v0);
        uint32_t id = uint32_t(i);
        std::memcpy(reinterpret_cast<char*>(&r.lo) + 12, &id, 4);
        root.bounds.grow(r.lo3(), r.hi);
        root.centroids.grow_point(r.centroid2());
    }
    return root;
}

NodeSplitter::NodeSplitter(PrimRef* refs, const BuildConfig& config)
    : m_refs(refs), m_config(config), m_stride((config.bins + 3) / 4 * 4), m_bins(3 * size_t(m_stride)),
      m_counts(3 * size_t(m_stride), 0), m_bins2(3 * size_t(m_stride)), m_counts2(3 * size_t(m_stride), 0),
      m_group_box(3 * size_t(m_stride)), m_group_count(3 * size_t(m_stride)), m_group_bin(3 * size_t(m_stride)),
      m_right_area(m_stride), m_right_count(m_stride) {}

void NodeSplitter::build_subtree(const WorkItem& root, BuildNodes& nodes) {
    // Depth-first over an explicit stack: the left child is split next, the right one waits.
    std::vector<WorkItem> stack;
    stack.reserve(2 * size_t(m_config.max_depth) + 2);
    stack.push_back(root);
    while (!stack.empty()) {
        const WorkItem item = stack.back();
        stack.pop_back();
        split_node(item, nodes, stack);
    }
}

BinMapper NodeSplitter::make_mapper(const Box& centroids, bool* usable) const {
    BinMapper map;
    float last = float(m_config.bins - 1);
    map.origin = centroids.lo;
    map.scale = Float4{0.0f, 0.0f, 0.0f, 0.0f};
    map.last = Float4{last, last, last, 0.0f};
    for (int a = 0; a < 3; ++a) {
        float extent = centroids.hi[a] - centroids.lo[a];
        float scale = extent > 0.0f ? float(m_config.bins) / extent : 0.0f;
        usable[a] = extent > 0.0f && std::isfinite(scale);
        map.scale[a] = usable[a] ? scale : 0.0f;
    }
    return map;
}

// Depth guard: a lopsided SAH split may leave a child more primitives than halving can bring
// to leaf size in the levels left; median splits keep median_levels_needed(count) <=
// max_depth - depth, which validate() checked at the root, so no leaf ends deeper than max_depth.
bool NodeSplitter::sah_split_fits_depth(const WorkItem& item, const Split& split) const {
    uint32_t count = item.end - item.begin, left = 0;
    const size_t base = split.axis * size_t(m_stride);
    for (uint32_t k = 0; k < m_groups[split.axis] && m_group_bin[base + k] < split.bin; ++k)
        left += m_group_count[base + k];
    uint32_t larger = std::max(left, count - left);
    return median_levels_needed(larger, m_config.max_leaf_size) + item.depth + 1 <= m_config.max_depth;
}

void NodeSplitter::split_node(const WorkItem& item, BuildNodes& nodes, std::vector<WorkItem>& stack) {
    const uint32_t count = item.end - item.begin;
    auto make_leaf = [&] {
        nodes[item.node].first = item.begin;
        nodes[item.node].count = count;
    };
    if (count == 1) return make_leaf();

    // Near max_depth only median splits (or leaves) are made, so binning is skipped there.
    bool deep = item.depth + 8 >= m_config.max_depth;
    bool usable[3];
    BinMapper map = make_mapper(item.centroids, usable);
    Split split = deep ? Split{} : find_sah_split(item.begin, item.end, map, usable);

    // Leaf when small enough and the SAH says splitting does not pay.
    float node_area = nodes[item.node].box.half_area();
    float leaf_cost = m_config.intersection_cost * float(count);
    float split_cost = node_area > 0.0f ? m_config.traversal_cost + m_config.intersection_cost * split.cost / node_area
                                        : kInf;
    if (count <= m_config.max_leaf_size && (split.axis < 0 || !(split_cost < leaf_cost))) return make_leaf();

    // Split by the SAH's bins, or at the object median when it found nothing or depth is short.
    Box left, right, left_c, right_c;
    uint32_t mid;
    if (split.axis >= 0 && sah_split_fits_depth(item, split)) {
        // The children's boxes from the filled bins in increasing order (empty bins add nothing).
        const size_t base = split.axis * size_t(m_stride);
        for (uint32_t k = 0; k < m_groups[split.axis]; ++k)
            (m_group_bin[base + k] < split.bin ? left : right).grow(m_group_box[base + k]);
        mid = partition_bins(item, split, map, left_c, right_c);
    } else {
        mid = partition_median(item, left, right, left_c, right_c);
    }

    // Children in an adjacent pair; the left one goes on top of the stack.
    uint32_t first_child = uint32_t(nodes.size());
    nodes[item.node].first = first_child;
    nodes[item.node].count = 0;
    nodes.emplace_back();
    nodes.emplace_back();
    nodes[first_child].box = left.to_aabb();
    nodes[first_child + 1].box = right.to_aabb();
    stack.push_back(WorkItem{first_child + 1, mid, item.end, item.depth + 1, right_c});
    stack.push_back(WorkItem{first_child, item.begin, mid, item.depth + 1, left_c});
}

// Groups the range's references by bin (the filled bins: their boxes, counts and indices), then
// sweeps each axis right-to-left and left-to-right to price every bin boundary (Wald 2007,
// section 3). Only boundaries that follow a filled bin are priced: one that follows an empty bin
// has the same two sides, so the same cost, as the one before it, which the strict "<" below
// keeps. The boxes are grown in the same order as over all bins (an empty box changes no bit of
// a min or max), so every cost is bit for bit the one the sweep over all bins computes.
Split NodeSplitter::find_sah_split(uint32_t begin, uint32_t end, const BinMapper& map, const bool* usable) {
    if (end - begin == 2) return split_pair(begin, map, usable);
    if (end - begin <= kSmallNode) group_small(begin, end, map, usable);
    else group_by_bins(begin, end, map);
    Split best;
    for (int a = 0; a < 3; ++a) {
        const uint32_t k = m_groups[a];
        if (!usable[a] || k < 2) continue;
        const size_t base = a * size_t(m_stride);
        const Box* box = &m_group_box[base];
        const uint32_t* counts = &m_group_count[base];
        Box acc;
        uint32_t acc_count = 0;
        for (uint32_t i = k - 1; i > 0; --i) {
            acc.grow(box[i]);
            acc_count += counts[i];
            m_right_area[i] = acc.half_area_nonempty();
            m_right_count[i] = acc_count;
        }
        acc = Box{};
        acc_count = 0;
        for (uint32_t i = 0; i + 1 < k; ++i) {
            acc.grow(box[i]);
            acc_count += counts[i];
            float cost = acc.half_area_nonempty() * float(acc_count) + m_right_area[i + 1] * float(m_right_count[i + 1]);
            if (cost < best.cost) best = Split{a, m_group_bin[base + i] + 1, cost};
        }
    }
    return best;
}

// In-place two-way partition by bin; each reference is classified once and its doubled
// centroid grows the bounds of its side. The branch follows the mesh's order, so it predicts
// well; what the loop waits on is the classification, so it is done on the split axis alone in
// scalar arithmetic (lane `axis` of BinMapper's, the same operations, so the same bin), and the
// bounds grow in registers (a reference parameter would keep them in memory, since the swaps
// might alias it). (A branch-free variant, sides classified in a first pass and moved in a
// second, was slower: 29% of the Sponza build against 21%.)
uint32_t NodeSplitter::partition_bins(const WorkItem& item, const Split& split, const BinMapper& map, Box& left_c,
                                      Box& right_c) {
    const int a = split.axis;
    const float origin = map.origin[a], scale = map.scale[a], last = map.last[a];
    const int32_t bin = int32_t(split.bin);
    auto is_left = [=](const PrimRef& r) {
        const float* v = reinterpret_cast<const float*>(&r);  // lo in floats 0..3, hi in 4..7
        float f = ((v[a] + v[4 + a]) - origin) * scale;
        f = f > 0.0f ? f : 0.0f;
        f = f < last ? f : last;
        return int32_t(f) < bin;
    };
    Box lc, rc;
    uint32_t i = item.begin, j = item.end;
    while (i < j) {
        const PrimRef& r = m_refs[i];
        const Float4 c = r.centroid2();
        if (is_left(r)) {
            lc.grow_point(c);
            ++i;
        } else {
            --j;
            std::swap(m_refs[i], m_refs[j]);
            rc.grow_point(c);
        }
    }
    left_c = lc;
    right_c = rc;
    return i;
}

// Object median on the largest centroid axis, ties broken by primitive id so the split is
// fully determined even when every centroid coincides.
uint32_t NodeSplitter::partition_median(const WorkItem& item, Box& left, Box& right, Box& left_c, Box& right_c) {
    int axis = item.centroids.to_aabb().largest_axis();
    uint32_t mid = item.begin + (item.end - item.begin) / 2;
    auto less = [axis](const PrimRef& x, const PrimRef& y) {
        float cx = x.centroid2()[axis], cy = y.centroid2()[axis];
        return cx < cy || (cx == cy && x.id() < y.id());
    };
    std::nth_element(m_refs + item.begin, m_refs + mid, m_refs + item.end, less);
    for (uint32_t i = item.begin; i < item.end; ++i) {
        const PrimRef& r = m_refs[i];
        (i < mid ? left : right).grow(r.lo3(), r.hi);
        (i < mid ? left_c : right_c).grow_point(r.centroid2());
    }
    return mid;
}

void validate(const BuildConfig& c, size_t triangle_count) {
    require(c.bins >= 2, "BuildConfig.bins must be at least 2 (got " + std::to_string(c.bins) + ")");
    require(c.max_leaf_size >= 1, "BuildConfig.max_leaf_size must be at least 1");
    require(c.max_depth >= 1 && c.max_depth <= kMaxSupportedDepth,
            "BuildConfig.max_depth must be in 1.." + std::to_string(kMaxSupportedDepth) +
                " (the traversal stack size), got " + std::to_string(c.max_depth));
    require(c.traversal_cost >= 0.0f && c.intersection_cost > 0.0f,
            "BuildConfig.traversal_cost must be >= 0 and intersection_cost > 0");
    require(triangle_count < (size_t(1) << 31), "build_bvh: too many triangles (>= 2^31)");
    uint32_t need = median_levels_needed(uint32_t(triangle_count), c.max_leaf_size);
    require(need <= c.max_depth, "BuildConfig.max_depth = " + std::to_string(c.max_depth) + " cannot hold " +
                                     std::to_string(triangle_count) + " triangles in leaves of max_leaf_size = " +
                                     std::to_string(c.max_leaf_size) + " (needs " + std::to_string(need) + ")");
}

}  // namespace binned_detail

uint32_t median_levels_needed(uint32_t count, uint32_t max_leaf_size) {
    uint32_t levels = 0;
    uint64_t capacity = max_leaf_size;
    while (capacity < count) {
        capacity *= 2;
        ++levels;
    }
    return levels;
}

BuildTree build_binned_sah(const std::vector<Triangle>& triangles, const BuildConfig& config, unsigned threads) {
    using namespace binned_detail;
    require(!triangles.empty(), "scene has no triangles");
    validate(config, triangles.size());
    const uint32_t n = uint32_t(triangles.size());
    PrimRefs refs;
    const RootBoxes root_boxes = make_refs(triangles, refs);
    BuildTree tree;
    tree.nodes.reserve(2 * size_t(n) - 1);
    tree.nodes.emplace_back();
    tree.nodes[0].box = root_boxes.bounds.to_aabb();
    const WorkItem root{0, 0, n, 0, root_boxes.centroids};
    if (threads > 1) build_parallel(refs, config, root, threads, tree.nodes);
    else NodeSplitter(refs.data(), config).build_subtree(root, tree.nodes);
    tree.prim_ids.resize(n);
    for (uint32_t i = 0; i < n; ++i) tree.prim_ids[i] = refs[i].id();
    return tree;
}

}  // namespace rtsim
