#pragma once
// Internals of the SBVH builder (sbvh_builder.h), shared by sbvh_builder.cpp (the node loop,
// object and median splits) and sbvh_spatial.cpp (spatial-split binning and splitting).
#include <cstdint>
#include <limits>
#include <vector>

#include "traces/bvh/build_tree.h"
#include "traces/bvh/sbvh_config.h"

namespace rtsim {
namespace sbvh_detail {

constexpr float kInf = std::numeric_limits<float>::infinity();
/// The traversal stack's size (kTraversalStackSize): deeper trees could overflow it.
constexpr uint32_t kMaxSupportedDepth = 64;

struct Ref {
    Aabb box;       ///< bounds of the part of the triangle this reference stands for
    uint32_t prim;  ///< scene triangle
};

struct Item {
    uint32_t node, depth;
    uint64_t budget;  ///< references this subtree may still add by spatial splits
    std::vector<Ref> refs;
};

struct Candidate {
    enum Kind { none, object, spatial };
    Kind kind = none;
    int axis = -1;
    float cost = kInf;             ///< sum over both sides of half area x references
    Aabb left, right;              ///< the children's boxes as binned
    uint32_t left_count = 0, right_count = 0;
    float origin = 0, scale = 0;   ///< object: centroid bin mapping of the axis
    uint32_t bin = 0;              ///< object: first bin of the right side
    float plane = 0;               ///< spatial: the split plane
};

inline float centroid2(const Ref& r, int a) { return r.box.lo[a] + r.box.hi[a]; }

inline Aabb overlap(const Aabb& a, const Aabb& b) {
    Aabb o{glm::max(a.lo, b.lo), glm::min(a.hi, b.hi)};
    return o.empty() ? Aabb{} : o;
}

inline Aabb joined(Aabb a, const Aabb& b) {
    a.grow(b);
    return a;
}

class SbvhBuilder {
public:
    SbvhBuilder(const std::vector<Triangle>& triangles, const BuildConfig& config, const SbvhConfig& sbvh)
        : m_tris(triangles), m_c(config), m_s(sbvh) {}

    BuildTree build(SbvhStats* stats);

private:
    void process(Item& item);
    Candidate object_split(const std::vector<Ref>& refs);
    Candidate spatial_split(const std::vector<Ref>& refs, const Aabb& box, uint64_t budget);
    void bin_spatial(const std::vector<Ref>& refs, const std::vector<float>* planes, const bool* usable);
    bool apply_object(const Item& item, const Candidate& c, std::vector<Ref>* l, std::vector<Ref>* r) const;
    bool apply_spatial(const Item& item, Candidate c, std::vector<Ref>* l, std::vector<Ref>* r);
    void apply_median(Item& item, std::vector<Ref>* l, std::vector<Ref>* r);
    void make_leaf(const Item& item);
    void push_children(Item& item, std::vector<Ref>&& l, std::vector<Ref>&& r);
    bool fits_depth(uint32_t depth, size_t larger) const {
        return median_levels_needed(uint32_t(larger), m_c.max_leaf_size) + depth + 1 <= m_c.max_depth;
    }

    const std::vector<Triangle>& m_tris;
    BuildConfig m_c;
    SbvhConfig m_s;
    float m_root_area = 0;
    BuildTree m_tree;
    SbvhStats m_stats;
    std::vector<Item> m_stack;
    // Binning scratch: object bins [axis * bins + b]; spatial bins of one axis.
    std::vector<Aabb> m_obox, m_rbox, m_sbox, m_pieces;
    std::vector<uint32_t> m_ocount, m_rcount, m_entry, m_exit;
};

}  // namespace sbvh_detail
}  // namespace rtsim
