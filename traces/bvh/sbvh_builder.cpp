// Spatial-split BVH builder (sbvh_builder.h): Stich, Friedrich & Dietrich 2009, "Spatial splits
// in bounding volume hierarchies". Section numbers below are the paper's. Nodes are split depth
// first; each work item owns its references (a triangle id and the box of the triangle's part it
// stands for), so a node's references can grow when a spatial split duplicates some.
#include "traces/bvh/sbvh_builder.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>

#include "traces/bvh/sbvh_builder_impl.h"
#include "traces/common/error.h"

namespace rtsim {
namespace sbvh_detail {

BuildTree SbvhBuilder::build(SbvhStats* stats) {
    Item root{0, 0, uint64_t(double(m_s.reference_budget) * double(m_tris.size())), {}};
    root.refs.resize(m_tris.size());
    Aabb box;
    for (size_t i = 0; i < m_tris.size(); ++i) {
        const Triangle& t = m_tris[i];
        for (const Vec3& v : {t.v0, t.v1, t.v2})
            if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
                throw Error("build_sbvh: triangle " + std::to_string(i) + " has a non-finite vertex");
        Aabb b;
        b.grow(t.v0), b.grow(t.v1), b.grow(t.v2);
        root.refs[i] = Ref{b, uint32_t(i)};
        box.grow(b);
    }
    m_tree.nodes.emplace_back();
    m_tree.nodes[0].box = box;
    m_root_area = box.half_area();
    m_stack.push_back(std::move(root));
    while (!m_stack.empty()) {
        Item item = std::move(m_stack.back());
        m_stack.pop_back();
        process(item);
    }
    m_stats.references = m_tree.prim_ids.size();
    if (stats) *stats = m_stats;
    return std::move(m_tree);
}

void SbvhBuilder::process(Item& item) {
    const size_t n = item.refs.size();
    if (n == 1) return make_leaf(item);
    // Near max_depth only median splits (or leaves) are made, as in the binned builder.
    const bool deep = item.depth + 8 >= m_c.max_depth;
    const Aabb box = m_tree.nodes[item.node].box;
    Candidate best = deep || !m_s.object_splits ? Candidate{} : object_split(item.refs);
    // Spatial splits only where the object split leaves the children overlapping (section 4.5).
    const bool overlapping = best.kind == Candidate::none ||
                             (m_root_area > 0 && overlap(best.left, best.right).half_area() > m_s.alpha * m_root_area);
    if (!deep && item.budget > 0 && overlapping) {
        const Candidate spatial = spatial_split(item.refs, box, item.budget);
        if (spatial.cost < best.cost) best = spatial;
    }
    const float node_area = box.half_area();
    const float leaf_cost = m_c.intersection_cost * float(n);
    const float split_cost = node_area > 0 ? m_c.traversal_cost + m_c.intersection_cost * best.cost / node_area : kInf;
    if (n <= m_c.max_leaf_size && (best.kind == Candidate::none || !(split_cost < leaf_cost))) return make_leaf(item);
    // Space subdivision alone (object_splits off): a split the SAH does not pay for, forced by the
    // leaf size, is an object median, which duplicates nothing.
    if (!m_s.object_splits && !(split_cost < leaf_cost)) best = Candidate{};

    std::vector<Ref> left, right;
    if (best.kind == Candidate::spatial && apply_spatial(item, best, &left, &right)) {
        ++m_stats.spatial_splits;
    } else if (best.kind == Candidate::spatial) {
        // The spatial split did not hold up (a side empty or too deep): the best object split.
        left.clear(), right.clear();
        const Candidate object = m_s.object_splits ? object_split(item.refs) : Candidate{};
        if (object.kind == Candidate::object && apply_object(item, object, &left, &right)) {
            ++m_stats.object_splits;
        } else {
            left.clear(), right.clear();
            apply_median(item, &left, &right);
        }
    } else if (best.kind == Candidate::object && apply_object(item, best, &left, &right)) {
        ++m_stats.object_splits;
    } else {
        left.clear(), right.clear();
        apply_median(item, &left, &right);
    }
    push_children(item, std::move(left), std::move(right));
}

// Binned SAH over reference centroids (Wald 2007, section 3), as the binned builder does.
Candidate SbvhBuilder::object_split(const std::vector<Ref>& refs) {
    const uint32_t nb = m_c.bins;
    Aabb cb;
    for (const Ref& r : refs)
        cb.grow(Vec3(centroid2(r, 0), centroid2(r, 1), centroid2(r, 2)));
    m_obox.assign(3 * size_t(nb), Aabb{});
    m_ocount.assign(3 * size_t(nb), 0);
    m_rbox.resize(nb);
    m_rcount.resize(nb);
    Candidate best;
    for (int a = 0; a < 3; ++a) {
        const float extent = cb.hi[a] - cb.lo[a], scale = float(nb) / extent;
        if (!(extent > 0.0f) || !std::isfinite(scale)) continue;
        Aabb* bins = &m_obox[a * size_t(nb)];
        uint32_t* counts = &m_ocount[a * size_t(nb)];
        for (const Ref& r : refs) {
            const float f = std::min(std::max((centroid2(r, a) - cb.lo[a]) * scale, 0.0f), float(nb - 1));
            bins[uint32_t(f)].grow(r.box);
            ++counts[uint32_t(f)];
        }
        Aabb acc;
        uint32_t count = 0;
        for (uint32_t b = nb - 1; b > 0; --b) {
            acc.grow(bins[b]);
            count += counts[b];
            m_rbox[b] = acc;
            m_rcount[b] = count;
        }
        acc = Aabb{};
        count = 0;
        for (uint32_t b = 1; b < nb; ++b) {
            acc.grow(bins[b - 1]);
            count += counts[b - 1];
            if (count == 0 || m_rcount[b] == 0) continue;
            const float cost = acc.half_area() * float(count) + m_rbox[b].half_area() * float(m_rcount[b]);
            if (cost < best.cost) {
                best = Candidate{Candidate::object, a, cost, acc, m_rbox[b], count, m_rcount[b], cb.lo[a], scale, b, 0};
            }
        }
    }
    return best;
}

bool SbvhBuilder::apply_object(const Item& item, const Candidate& c, std::vector<Ref>* l, std::vector<Ref>* r) const {
    if (!fits_depth(item.depth, std::max(c.left_count, c.right_count))) return false;
    const float last = float(m_c.bins - 1);
    for (const Ref& ref : item.refs) {
        const float f = std::min(std::max((centroid2(ref, c.axis) - c.origin) * c.scale, 0.0f), last);
        (uint32_t(f) < c.bin ? l : r)->push_back(ref);
    }
    return !l->empty() && !r->empty();
}

// Object median on the largest centroid axis; ties by primitive and box so the split is fully
// determined even when references coincide.
void SbvhBuilder::apply_median(Item& item, std::vector<Ref>* l, std::vector<Ref>* r) {
    Aabb cb;
    for (const Ref& ref : item.refs) cb.grow(Vec3(centroid2(ref, 0), centroid2(ref, 1), centroid2(ref, 2)));
    const int a = cb.largest_axis();
    auto key = [a](const Ref& x) {
        return std::make_tuple(centroid2(x, a), x.prim, x.box.lo.x, x.box.lo.y, x.box.lo.z, x.box.hi.x, x.box.hi.y,
                               x.box.hi.z);
    };
    const size_t mid = item.refs.size() / 2;
    std::nth_element(item.refs.begin(), item.refs.begin() + mid, item.refs.end(),
                     [&](const Ref& x, const Ref& y) { return key(x) < key(y); });
    l->assign(item.refs.begin(), item.refs.begin() + mid);
    r->assign(item.refs.begin() + mid, item.refs.end());
    ++m_stats.median_splits;
}

void SbvhBuilder::make_leaf(const Item& item) {
    BuildNode& node = m_tree.nodes[item.node];
    node.first = uint32_t(m_tree.prim_ids.size());
    node.count = uint32_t(item.refs.size());
    for (const Ref& r : item.refs) m_tree.prim_ids.push_back(r.prim);
}

void SbvhBuilder::push_children(Item& item, std::vector<Ref>&& l, std::vector<Ref>&& r) {
    const uint64_t nl = l.size(), nr = r.size(), added = nl + nr - item.refs.size();
    // What the split did not use is shared in proportion to the children's references.
    const uint64_t rest = item.budget - std::min(item.budget, added);
    const uint64_t left_budget = rest * nl / (nl + nr);
    const uint32_t first = uint32_t(m_tree.nodes.size());
    m_tree.nodes[item.node].first = first;
    m_tree.nodes[item.node].count = 0;
    Aabb lb, rb;
    for (const Ref& ref : l) lb.grow(ref.box);
    for (const Ref& ref : r) rb.grow(ref.box);
    m_tree.nodes.emplace_back();
    m_tree.nodes.emplace_back();
    m_tree.nodes[first].box = lb;
    m_tree.nodes[first + 1].box = rb;
    item.refs.clear();
    item.refs.shrink_to_fit();
    // The left child goes on top of the stack: leaves come out in left-before-right order.
    m_stack.push_back(Item{first + 1, item.depth + 1, rest - left_budget, std::move(r)});
    m_stack.push_back(Item{first, item.depth + 1, left_budget, std::move(l)});
}

}  // namespace sbvh_detail

using sbvh_detail::kMaxSupportedDepth;

BuildTree build_sbvh(const std::vector<Triangle>& triangles, const BuildConfig& config, const SbvhConfig& sbvh,
                     SbvhStats* stats) {
    require(!triangles.empty(), "scene has no triangles");
    require(config.bins >= 2, "BuildConfig.bins must be at least 2");
    require(config.max_leaf_size >= 1, "BuildConfig.max_leaf_size must be at least 1");
    require(config.max_depth >= 1 && config.max_depth <= kMaxSupportedDepth,
            "BuildConfig.max_depth must be in 1.." + std::to_string(kMaxSupportedDepth));
    require(config.traversal_cost >= 0.0f && config.intersection_cost > 0.0f,
            "BuildConfig.traversal_cost must be >= 0 and intersection_cost > 0");
    require(sbvh.spatial_bins >= 2 && sbvh.spatial_bins <= 1024, "SbvhConfig.spatial_bins must be in 2..1024");
    require(sbvh.alpha >= 0.0f && sbvh.reference_budget >= 0.0f && sbvh.reference_budget <= 16.0f,
            "SbvhConfig.alpha must be >= 0 and reference_budget in [0, 16]");
    require(triangles.size() < (size_t(1) << 30), "build_sbvh: too many triangles (>= 2^30)");
    const uint32_t need = median_levels_needed(uint32_t(triangles.size()), config.max_leaf_size);
    require(need <= config.max_depth, "BuildConfig.max_depth = " + std::to_string(config.max_depth) +
                                          " cannot hold " + std::to_string(triangles.size()) + " triangles");
    return sbvh_detail::SbvhBuilder(triangles, config, sbvh).build(stats);
}

}  // namespace rtsim
