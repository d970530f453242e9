// Binned SAH builder (Wald 2007, "On fast construction of SAH-based bounding volume
// hierarchies"), written in the manner of madmann91/bvh v2's binned_sah_builder.h: primitives
// become compact 32-byte references that are binned by centroid and partitioned in place, so a
// node costs two linear passes over its range and nothing is allocated per node.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "traces/bvh/build_tree.h"
#include "traces/common/error.h"

namespace rtsim {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
/// Equals kTraversalStackSize (traces/isect/traversal.h): deeper trees could overflow it.
constexpr uint32_t kMaxSupportedDepth = 64;

// Four-lane vectors (GCC/Clang vector extensions, portable across ISAs): lanes 0..2 are x, y, z;
// lane 3 of every value that enters arithmetic is 0, so it never holds a denormal or NaN.
typedef float Float4 __attribute__((vector_size(16)));
typedef int32_t Int4 __attribute__((vector_size(16)));

inline Float4 vmin(Float4 a, Float4 b) { return a < b ? a : b; }
inline Float4 vmax(Float4 a, Float4 b) { return a > b ? a : b; }

/// One primitive's box; the primitive id rides in lane 3 of lo, masked off before arithmetic.
struct PrimRef {
    Float4 lo;
    Float4 hi;  // lane 3 = 0
    uint32_t id() const {
        uint32_t v;
        std::memcpy(&v, reinterpret_cast<const char*>(&lo) + 12, 4);
        return v;
    }
    Float4 lo3() const {
        return Float4(Int4(lo) & Int4{-1, -1, -1, 0});  // vector casts reinterpret the bits
    }
    /// The centroid kept doubled (lo + hi): saves a multiply per use.
    Float4 centroid2() const { return lo3() + hi; }
};
static_assert(sizeof(PrimRef) == 32, "PrimRef should stay half a cache line");

struct Box {
    Float4 lo = {kInf, kInf, kInf, 0.0f};
    Float4 hi = {-kInf, -kInf, -kInf, 0.0f};

    void grow(Float4 lo_in, Float4 hi_in) {
        lo = vmin(lo, lo_in);
        hi = vmax(hi, hi_in);
    }
    void grow(const Box& b) { grow(b.lo, b.hi); }
    void grow_point(Float4 p) { grow(p, p); }
    /// Half the surface area, garbage for an empty box: the SAH sweeps skip empty sides.
    float half_area_nonempty() const {
        Float4 e = hi - lo;
        return e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
    }
    Aabb to_aabb() const { return Aabb{Vec3(lo[0], lo[1], lo[2]), Vec3(hi[0], hi[1], hi[2])}; }
};

/// A node waiting to be split: its range of references and the bounds of their centroids.
struct WorkItem {
    uint32_t node, begin, end, depth;
    Box centroids;  // doubled centroids
};

struct Split {
    int axis = -1;      // -1: no valid SAH split
    uint32_t bin = 0;   // first bin of the right side
    float cost = kInf;  // sum over sides of half_area x count
};

/// Maps a doubled centroid to its bin on all three axes at once; the same arithmetic serves
/// binning and partitioning, so both sides of a chosen split are non-empty.
struct BinMapper {
    Float4 origin, scale, last;
    Int4 operator()(const PrimRef& r) const {
        Float4 f = (r.centroid2() - origin) * scale;
        Float4 zero = {0.0f, 0.0f, 0.0f, 0.0f};
        f = f > zero ? f : zero;  // also maps NaN to bin 0
        f = f < last ? f : last;
        return __builtin_convertvector(f, Int4);
    }
};

class BinnedSahBuilder {
public:
    BinnedSahBuilder(const std::vector<Triangle>& triangles, const BuildConfig& config)
        : m_triangles(triangles), m_config(config), m_bins(3 * size_t(config.bins)),
          m_counts(3 * size_t(config.bins)), m_right_area(config.bins),
          m_right_count(config.bins) {}

    BuildTree build();

private:
    Box make_refs();
    BinMapper make_mapper(const Box& centroids, bool* usable) const;
    bool sah_split_fits_depth(const WorkItem& item, const Split& split) const;
    void split_node(const WorkItem& item);
    Split find_sah_split(uint32_t begin, uint32_t end, const BinMapper& map, const bool* usable);
    uint32_t partition_bins(const WorkItem& item, const Split& split, const BinMapper& map,
                            Box& left_c, Box& right_c);
    uint32_t partition_median(const WorkItem& item, Box& left, Box& right, Box& left_c,
                              Box& right_c);
    void make_leaf(const WorkItem& item) {
        m_tree.nodes[item.node].first = item.begin;
        m_tree.nodes[item.node].count = item.end - item.begin;
    }

    const std::vector<Triangle>& m_triangles;
    BuildConfig m_config;
    std::vector<PrimRef> m_refs;
    std::vector<Box> m_bins;           // [axis * bins + bin]
    std::vector<uint32_t> m_counts;    // [axis * bins + bin]
    std::vector<float> m_right_area;
    std::vector<uint32_t> m_right_count;
    std::vector<WorkItem> m_stack;
    BuildTree m_tree;
};

// Per-primitive boxes, rejecting non-finite vertices (docs/architecture.md, rule 11); returns the centroid bounds.
Box BinnedSahBuilder::make_refs() {
    m_refs.resize(m_triangles.size());
    Box centroids;
    for (size_t i = 0; i < m_triangles.size(); ++i) {
        const Triangle& t = m_triangles[i];
        PrimRef& r = m_refs[i];
        for (int a = 0; a < 3; ++a) {
            r.lo[a] = std::min(t.v0[a], std::min(t.v1[a], t.v2[a]));
            r.hi[a] = std::max(t.v0[a], std::max(t.v1[a], t.v2[a]));
            if (!std::isfinite(t.v0[a]) || !std::isfinite(t.v1[a]) || !std::isfinite(t.v2[a]))
                throw Error("build_bvh: triangle " + std::to_string(i) + " has a non-finite vertex");
        }
        uint32_t id = uint32_t(i);
        std::memcpy(reinterpret_cast<char*>(&r.lo) + 12, &id, 4);
        r.hi[3] = 0.0f;
        centroids.grow_point(r.centroid2());
    }
    return centroids;
}

BuildTree BinnedSahBuilder::build() {
    const uint32_t n = uint32_t(m_triangles.size());
    Box root_c = make_refs();
    m_tree.nodes.reserve(2 * size_t(n) - 1);
    m_tree.nodes.emplace_back();
    Box root_box;
    for (const PrimRef& r : m_refs) root_box.grow(r.lo3(), r.hi);
    m_tree.nodes[0].box = root_box.to_aabb();

    // Depth-first over an explicit stack: the left child is split next, the right one waits.
    m_stack.reserve(2 * size_t(m_config.max_depth) + 2);
    m_stack.push_back(WorkItem{0, 0, n, 0, root_c});
    while (!m_stack.empty()) {
        WorkItem item = m_stack.back();
        m_stack.pop_back();
        split_node(item);
    }
    m_tree.prim_ids.resize(n);
    for (uint32_t i = 0; i < n; ++i) m_tree.prim_ids[i] = m_refs[i].id();
    return std::move(m_tree);
}

BinMapper BinnedSahBuilder::make_mapper(const Box& centroids, bool* usable) const {
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
bool BinnedSahBuilder::sah_split_fits_depth(const WorkItem& item, const Split& split) const {
    uint32_t count = item.end - item.begin, left = 0;
    for (uint32_t b = 0; b < split.bin; ++b) left += m_counts[split.axis * m_config.bins + b];
    uint32_t larger = std::max(left, count - left);
    return median_levels_needed(larger, m_config.max_leaf_size) + item.depth + 1 <=
           m_config.max_depth;
}

void BinnedSahBuilder::split_node(const WorkItem& item) {
    const uint32_t count = item.end - item.begin;
    if (count == 1) return make_leaf(item);

    // Near max_depth only median splits (or leaves) are made, so binning is skipped there.
    bool deep = item.depth + 8 >= m_config.max_depth;
    bool usable[3];
    BinMapper map = make_mapper(item.centroids, usable);
    Split split = deep ? Split{} : find_sah_split(item.begin, item.end, map, usable);

    // Leaf when small enough and the SAH says splitting does not pay.
    float node_area = m_tree.nodes[item.node].box.half_area();
    float leaf_cost = m_config.intersection_cost * float(count);
    float split_cost = node_area > 0.0f ? m_config.traversal_cost +
                                              m_config.intersection_cost * split.cost / node_area
                                        : kInf;
    if (count <= m_config.max_leaf_size && (split.axis < 0 || !(split_cost < leaf_cost)))
        return make_leaf(item);

    // Split by the SAH's bins, or at the object median when it found nothing or depth is short.
    Box left, right, left_c, right_c;
    uint32_t mid;
    if (split.axis >= 0 && sah_split_fits_depth(item, split)) {
        const Box* bins = &m_bins[split.axis * m_config.bins];
        for (uint32_t b = 0; b < split.bin; ++b) left.grow(bins[b]);
        for (uint32_t b = split.bin; b < m_config.bins; ++b) right.grow(bins[b]);
        mid = partition_bins(item, split, map, left_c, right_c);
    } else {
        mid = partition_median(item, left, right, left_c, right_c);
    }

    // Children in an adjacent pair; the left one goes on top of the stack.
    uint32_t first_child = uint32_t(m_tree.nodes.size());
    m_tree.nodes[item.node].first = first_child;
    m_tree.nodes[item.node].count = 0;
    m_tree.nodes.emplace_back();
    m_tree.nodes.emplace_back();
    m_tree.nodes[first_child].box = left.to_aabb();
    m_tree.nodes[first_child + 1].box = right.to_aabb();
    m_stack.push_back(WorkItem{first_child + 1, mid, item.end, item.depth + 1, right_c});
    m_stack.push_back(WorkItem{first_child, item.begin, mid, item.depth + 1, left_c});
}

// Fills the bins in one pass over the range, then sweeps each axis right-to-left and
// left-to-right to price every bin boundary (Wald 2007, section 3).
Split BinnedSahBuilder::find_sah_split(uint32_t begin, uint32_t end, const BinMapper& map,
                                       const bool* usable) {
    const uint32_t nbins = m_config.bins;
    std::fill(m_bins.begin(), m_bins.end(), Box{});
    std::fill(m_counts.begin(), m_counts.end(), 0u);
    Box* bins[3] = {&m_bins[0], &m_bins[nbins], &m_bins[2 * size_t(nbins)]};
    uint32_t* counts[3] = {&m_counts[0], &m_counts[nbins], &m_counts[2 * size_t(nbins)]};
    for (uint32_t i = begin; i < end; ++i) {
        const PrimRef& r = m_refs[i];
        Float4 lo = r.lo3();
        Int4 index = map(r);
        for (int a = 0; a < 3; ++a) {
            bins[a][index[a]].grow(lo, r.hi);
            ++counts[a][index[a]];
        }
    }
    Split best;
    for (int a = 0; a < 3; ++a) {
        if (!usable[a]) continue;
        Box acc;
        uint32_t acc_count = 0;
        for (uint32_t b = nbins - 1; b > 0; --b) {
            acc.grow(bins[a][b]);
            acc_count += counts[a][b];
            m_right_area[b] = acc.half_area_nonempty();
            m_right_count[b] = acc_count;
        }
        acc = Box{};
        acc_count = 0;
        for (uint32_t b = 1; b < nbins; ++b) {
            acc.grow(bins[a][b - 1]);
            acc_count += counts[a][b - 1];
            if (acc_count == 0 || m_right_count[b] == 0) continue;
            float cost = acc.half_area_nonempty() * float(acc_count) +
                         m_right_area[b] * float(m_right_count[b]);
            if (cost < best.cost) best = Split{a, b, cost};
        }
    }
    return best;
}

// In-place two-way partition by bin; each reference is classified once and its doubled
// centroid grows the bounds of its side.
uint32_t BinnedSahBuilder::partition_bins(const WorkItem& item, const Split& split,
                                          const BinMapper& map, Box& left_c, Box& right_c) {
    uint32_t i = item.begin, j = item.end;
    while (i < j) {
        const PrimRef& r = m_refs[i];
        Float4 c = r.centroid2();
        if (uint32_t(map(r)[split.axis]) < split.bin) {
            left_c.grow_point(c);
            ++i;
        } else {
            --j;
            std::swap(m_refs[i], m_refs[j]);
            right_c.grow_point(c);
        }
    }
    return i;
}

// Object median on the largest centroid axis, ties broken by primitive id so the split is
// fully determined even when every centroid coincides.
uint32_t BinnedSahBuilder::partition_median(const WorkItem& item, Box& left, Box& right,
                                            Box& left_c, Box& right_c) {
    int axis = item.centroids.to_aabb().largest_axis();
    uint32_t mid = item.begin + (item.end - item.begin) / 2;
    auto less = [axis](const PrimRef& x, const PrimRef& y) {
        float cx = x.centroid2()[axis], cy = y.centroid2()[axis];
        return cx < cy || (cx == cy && x.id() < y.id());
    };
    std::nth_element(m_refs.begin() + item.begin, m_refs.begin() + mid, m_refs.begin() + item.end,
                     less);
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
    require(need <= c.max_depth, "BuildConfig.max_depth = " + std::to_string(c.max_depth) +
                                     " cannot hold " + std::to_string(triangle_count) +
                                     " triangles in leaves of max_leaf_size = " +
                                     std::to_string(c.max_leaf_size) + " (needs " +
                                     std::to_string(need) + ")");
}

}  // namespace

uint32_t median_levels_needed(uint32_t count, uint32_t max_leaf_size) {
    uint32_t levels = 0;
    uint64_t capacity = max_leaf_size;
    while (capacity < count) {
        capacity *= 2;
        ++levels;
    }
    return levels;
}

BuildTree build_binned_sah(const std::vector<Triangle>& triangles, const BuildConfig& config) {
    require(!triangles.empty(), "scene has no triangles");
    validate(config, triangles.size());
    return BinnedSahBuilder(triangles, config).build();
}

}  // namespace rtsim
