// The GK-BVH's boxes variant (gkbvh.h): space subdivision with references' boxes cut at the
// plane, priced by a full sweep (Popov et al. 2009). Each work item owns its references (a
// triangle and the box of the part it stands for), as in the spatial-split builder.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>
#include <tuple>

#include "traces/accel/gkbvh/gkbvh.h"
#include "traces/common/error.h"

namespace rtsim {
namespace gk_detail {

constexpr float kInf = std::numeric_limits<float>::infinity();
/// The traversal stack's size (kTraversalStackSize): deeper trees could overflow it.
constexpr uint32_t kMaxSupportedDepth = 64;

struct Ref {
    Aabb box;       ///< bounds of the part of the triangle this reference stands for
    uint32_t prim;  ///< scene triangle
};

struct Item {
    uint32_t node, depth;
    uint64_t budget;  ///< references this subtree may still add
    std::vector<Ref> refs;
};

struct Plane {
    int axis = -1;
    float position = 0;
    float cost = kInf;  ///< sum over both sides of half area x references
};

class GkSweepBuilder {
public:
    GkSweepBuilder(const std::vector<Triangle>& tris, const BuildConfig& c, const GkConfig& gk)
        : m_tris(tris), m_c(c), m_gk(gk) {}

    BuildTree build(GkStats* stats) {
        Item root{0, 0, uint64_t(double(m_gk.reference_budget) * double(m_tris.size())), {}};
        root.refs.resize(m_tris.size());
        Aabb box;
        for (size_t i = 0; i < m_tris.size(); ++i) {
            Aabb b;
            for (const Vec3& v : {m_tris[i].v0, m_tris[i].v1, m_tris[i].v2}) {
                require(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z),
                        "gkbvh: triangle " + std::to_string(i) + " has a non-finite vertex");
                b.grow(v);
            }
            root.refs[i] = Ref{b, uint32_t(i)};
            box.grow(b);
        }
        m_tree.nodes.emplace_back();
        m_tree.nodes[0].box = box;
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

private:
    bool fits_depth(uint32_t depth, size_t larger) const {
        return median_levels_needed(uint32_t(larger), m_c.max_leaf_size) + depth + 1 <= m_c.max_depth;
    }

    void process(Item& item) {
        const size_t n = item.refs.size();
        if (n == 1) return make_leaf(item);
        const bool deep = item.depth + 8 >= m_c.max_depth;
        const Aabb box = m_tree.nodes[item.node].box;
        const Plane best = deep ? Plane{} : sweep(item.refs, box, item.budget);
        const float area = box.half_area();
        const float leaf_cost = m_c.intersection_cost * float(n);
        const float split_cost = area > 0 ? m_c.traversal_cost + m_c.intersection_cost * best.cost / area : kInf;
        if (n <= m_c.max_leaf_size && (best.axis < 0 || !(split_cost < leaf_cost))) return make_leaf(item);
        std::vector<Ref> left, right;
        // A plane only where the SAH pays for it; a split forced by the leaf size is an object
        // median, which duplicates nothing.
        if (best.axis >= 0 && split_cost < leaf_cost && apply(item, best, &left, &right)) {
            ++m_stats.spatial_splits;
        } else {
            left.clear(), right.clear();
            median(item, &left, &right);
        }
        push_children(item, std::move(left), std::move(right));
    }

    // The full sweep, one axis at a time: the left side of plane p holds the references starting
    // before p (their boxes cut at p), the right side those ending after it. Prefix unions in
    // order of the boxes' low ends and suffix unions in order of their high ends give both
    // sides' boxes at every candidate plane (every box end strictly inside the node) exactly.
    Plane sweep(const std::vector<Ref>& refs, const Aabb& box, uint64_t budget) {
        const size_t n = refs.size();
        Plane best;
        m_by_lo.resize(n), m_by_hi.resize(n), m_prefix.resize(n + 1), m_suffix.resize(n + 1);
        for (int a = 0; a < 3; ++a) {
            if (!(box.lo[a] < box.hi[a])) continue;
            std::iota(m_by_lo.begin(), m_by_lo.end(), 0u);
            std::iota(m_by_hi.begin(), m_by_hi.end(), 0u);
            std::sort(m_by_lo.begin(), m_by_lo.end(), [&](uint32_t x, uint32_t y) { return refs[x].box.lo[a] < refs[y].box.lo[a]; });
            std::sort(m_by_hi.begin(), m_by_hi.end(), [&](uint32_t x, uint32_t y) { return refs[x].box.hi[a] < refs[y].box.hi[a]; });
            m_prefix[0] = Aabb{};
            for (size_t k = 0; k < n; ++k) (m_prefix[k + 1] = m_prefix[k]).grow(refs[m_by_lo[k]].box);
            m_suffix[n] = Aabb{};
            for (size_t k = n; k-- > 0;) (m_suffix[k] = m_suffix[k + 1]).grow(refs[m_by_hi[k]].box);
            m_planes.clear();
            for (const Ref& r : refs)
                for (float p : {r.box.lo[a], r.box.hi[a]})
                    if (p > box.lo[a] && p < box.hi[a]) m_planes.push_back(p);
            std::sort(m_planes.begin(), m_planes.end());
            m_planes.erase(std::unique(m_planes.begin(), m_planes.end()), m_planes.end());
            size_t starts = 0, ends = 0;  // references with lo < p; with hi <= p
            for (float p : m_planes) {
                while (starts < n && refs[m_by_lo[starts]].box.lo[a] < p) ++starts;
                while (ends < n && refs[m_by_hi[ends]].box.hi[a] <= p) ++ends;
                const size_t nl = starts, nr = n - ends;
                if (nl == 0 || nr == 0 || nl >= n || nr >= n || nl + nr > n + budget) continue;
                Aabb l = m_prefix[nl], r = m_suffix[ends];
                l.hi[a] = std::min(l.hi[a], p);
                r.lo[a] = std::max(r.lo[a], p);
                const float cost = l.half_area() * float(nl) + r.half_area() * float(nr);
                if (cost < best.cost) best = Plane{a, p, cost};
            }
        }
        return best;
    }

    bool apply(const Item& item, const Plane& plane, std::vector<Ref>* l, std::vector<Ref>* r) const {
        const int a = plane.axis;
        const float p = plane.position;
        for (const Ref& ref : item.refs) {
            if (ref.box.hi[a] <= p) {
                l->push_back(ref);
            } else if (ref.box.lo[a] >= p) {
                r->push_back(ref);
            } else {  // straddling: each side gets the box cut at the plane
                Ref lr = ref, rr = ref;
                lr.box.hi[a] = p;
                rr.box.lo[a] = p;
                l->push_back(lr);
                r->push_back(rr);
            }
        }
        const size_t n = item.refs.size();
        return !l->empty() && !r->empty() && l->size() < n && r->size() < n &&
               l->size() + r->size() - n <= item.budget && fits_depth(item.depth, std::max(l->size(), r->size()));
    }

    // Object median on the largest centroid axis; ties by primitive and box (references of one
    // primitive may coincide), so the split is fully determined.
    void median(Item& item, std::vector<Ref>* l, std::vector<Ref>* r) {
        Aabb cb;
        for (const Ref& ref : item.refs) cb.grow(ref.box.center());
        const int a = cb.largest_axis();
        auto key = [a](const Ref& x) {
            return std::make_tuple(x.box.lo[a] + x.box.hi[a], x.prim, x.box.lo.x, x.box.lo.y, x.box.lo.z, x.box.hi.x,
                                   x.box.hi.y, x.box.hi.z);
        };
        const size_t mid = item.refs.size() / 2;
        std::nth_element(item.refs.begin(), item.refs.begin() + mid, item.refs.end(),
                         [&](const Ref& x, const Ref& y) { return key(x) < key(y); });
        l->assign(item.refs.begin(), item.refs.begin() + mid);
        r->assign(item.refs.begin() + mid, item.refs.end());
        ++m_stats.median_splits;
    }

    void make_leaf(const Item& item) {
        BuildNode& node = m_tree.nodes[item.node];
        node.first = uint32_t(m_tree.prim_ids.size());
        node.count = uint32_t(item.refs.size());
        for (const Ref& r : item.refs) m_tree.prim_ids.push_back(r.prim);
    }

    void push_children(Item& item, std::vector<Ref>&& l, std::vector<Ref>&& r) {
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
        // The left child on top of the stack: leaves come out in left-before-right order.
        m_stack.push_back(Item{first + 1, item.depth + 1, rest - left_budget, std::move(r)});
        m_stack.push_back(Item{first, item.depth + 1, left_budget, std::move(l)});
    }

    const std::vector<Triangle>& m_tris;
    BuildConfig m_c;
    GkConfig m_gk;
    BuildTree m_tree;
    GkStats m_stats;
    std::vector<Item> m_stack;
    std::vector<uint32_t> m_by_lo, m_by_hi;  // sweep scratch
    std::vector<Aabb> m_prefix, m_suffix;
    std::vector<float> m_planes;
};

}  // namespace gk_detail

BuildTree build_gk_boxes(const std::vector<Triangle>& triangles, const BuildConfig& config, const GkConfig& gk,
                         GkStats* stats) {
    require(!triangles.empty(), "scene has no triangles");
    require(config.max_leaf_size >= 1, "BuildConfig.max_leaf_size must be at least 1");
    require(config.max_depth >= 1 && config.max_depth <= gk_detail::kMaxSupportedDepth,
            "BuildConfig.max_depth must be in 1.." + std::to_string(gk_detail::kMaxSupportedDepth));
    require(config.traversal_cost >= 0.0f && config.intersection_cost > 0.0f,
            "BuildConfig.traversal_cost must be >= 0 and intersection_cost > 0");
    require(gk.reference_budget >= 0.0f && gk.reference_budget <= 16.0f, "GkConfig.reference_budget must be in [0, 16]");
    require(triangles.size() < (size_t(1) << 30), "gkbvh: too many triangles (>= 2^30)");
    const uint32_t need = median_levels_needed(uint32_t(triangles.size()), config.max_leaf_size);
    require(need <= config.max_depth, "BuildConfig.max_depth = " + std::to_string(config.max_depth) + " cannot hold " +
                                          std::to_string(triangles.size()) + " triangles");
    return gk_detail::GkSweepBuilder(triangles, config, gk).build(stats);
}

}  // namespace rtsim
