#pragma once
// Internals of the binned SAH builder (build_tree.h, build_binned_sah), shared by
// binned_sah_builder.cpp (references, the node split, the single-threaded build),
// binned_sah_groups.cpp (a node's references grouped by bin for the SAH sweep) and
// binned_sah_parallel.cpp (the multi-threaded build, which splits the same nodes the same way).
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "traces/bvh/build_tree.h"
#include "traces/common/huge_pages.h"

namespace rtsim {
namespace binned_detail {

constexpr float kInf = std::numeric_limits<float>::infinity();

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
/// The build's references (8 MB on Sponza), partitioned in place node after node: on huge pages.
using PrimRefs = std::vector<PrimRef, HugePageAllocator<PrimRef>>;

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

/// Splits nodes of one tree over a shared array of references (each call touches only its
/// node's range), appending children to a node array and their work items to a stack. One per
/// thread: it owns the bins and sweep scratch. Bins stay empty between nodes: a node resets only
/// the bins it filled, and the sweeps visit only non-empty bins (see find_sah_split), which is
/// what makes the many small nodes near the leaves cheap.
class NodeSplitter {
public:
    /// Nodes of at most this many references are grouped by sorting instead of binning.
    static constexpr uint32_t kSmallNode = 8;

    NodeSplitter(PrimRef* refs, const BuildConfig& config);

    /// Splits `item` (a node of `nodes`) or makes it a leaf; children go to the end of `nodes`
    /// and their items onto `stack`, the left one on top.
    void split_node(const WorkItem& item, BuildNodes& nodes, std::vector<WorkItem>& stack);
    /// Splits `root` and everything below it, depth first.
    void build_subtree(const WorkItem& root, BuildNodes& nodes);

private:
    BinMapper make_mapper(const Box& centroids, bool* usable) const;
    bool sah_split_fits_depth(const WorkItem& item, const Split& split) const;
    Split find_sah_split(uint32_t begin, uint32_t end, const BinMapper& map, const bool* usable);
    void group_by_bins(uint32_t begin, uint32_t end, const BinMapper& map);
    void group_small(uint32_t begin, uint32_t end, const BinMapper& map, const bool* usable);
    Split split_pair(uint32_t begin, const BinMapper& map, const bool* usable);
    uint32_t partition_bins(const WorkItem& item, const Split& split, const BinMapper& map, Box& left_c,
                            Box& right_c);
    uint32_t partition_median(const WorkItem& item, Box& left, Box& right, Box& left_c, Box& right_c);

    PrimRef* m_refs;
    BuildConfig m_config;
    uint32_t m_stride;                  // bins per axis, rounded up to 4 (counts are scanned 4 at a time)
    std::vector<Box> m_bins;            // [axis * stride + bin], empty between nodes
    std::vector<uint32_t> m_counts;     // [axis * stride + bin], 0 between nodes
    std::vector<Box> m_bins2;           // the second stream's bins (fill_bins), empty between nodes
    std::vector<uint32_t> m_counts2;
    // The node's filled bins ("groups") per axis in increasing bin order, [axis * stride + k]:
    // their boxes, reference counts and bin indices; m_groups[axis] of them.
    std::vector<Box> m_group_box;
    std::vector<uint32_t> m_group_count;
    std::vector<uint32_t> m_group_bin;
    uint32_t m_groups[3] = {0, 0, 0};
    std::vector<float> m_right_area;    // per group k: the box of groups k.. of the axis
    std::vector<uint32_t> m_right_count;
};

/// Throws rtsim::Error if the config is unusable or cannot hold `triangle_count` triangles.
void validate(const BuildConfig& c, size_t triangle_count);
/// The root's box over all references and the bounds of their (doubled) centroids.
struct RootBoxes {
    Box bounds, centroids;
};
/// Per-primitive references (rejecting non-finite vertices), and the root's boxes.
RootBoxes make_refs(const std::vector<Triangle>& triangles, PrimRefs& refs);

/// The multi-threaded build (binned_sah_parallel.cpp): the same splits on `threads` threads,
/// and the same tree, node for node, as NodeSplitter::build_subtree from the root.
void build_parallel(PrimRefs& refs, const BuildConfig& config, const WorkItem& root,
                    unsigned threads, BuildNodes& nodes);

}  // namespace binned_detail
}  // namespace rtsim
