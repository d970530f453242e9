// The full-sweep SAH and equal-count builders (sweep_builder.h).
#include "traces/bvh/sweep_builder.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "traces/common/error.h"

namespace rtsim {
namespace sweep_detail {

/// The traversal stack's size (kTraversalStackSize): deeper trees could overflow it.
constexpr uint32_t kMaxSupportedDepth = 64;

struct Item {
    uint32_t node, begin, end, depth;
};

class ObjectBuilder {
public:
    ObjectBuilder(const std::vector<Triangle>& tris, const BuildConfig& c, bool sah) : m_c(c), m_sah(sah) {
        const size_t n = tris.size();
        m_box.resize(n);
        m_c2.resize(n);
        for (size_t i = 0; i < n; ++i) {
            for (const Vec3& v : {tris[i].v0, tris[i].v1, tris[i].v2}) {
                require(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z),
                        "build_bvh: triangle " + std::to_string(i) + " has a non-finite vertex");
                m_box[i].grow(v);
            }
            m_c2[i] = m_box[i].lo + m_box[i].hi;
        }
    }

    BuildTree build() {
        const uint32_t n = uint32_t(m_box.size());
        m_tree.prim_ids.resize(n);
        for (uint32_t i = 0; i < n; ++i) m_tree.prim_ids[i] = i;
        m_tree.nodes.reserve(2 * size_t(n));
        m_tree.nodes.emplace_back();
        m_tree.nodes[0].box = range_box(0, n);
        std::vector<Item> stack{{0, 0, n, 0}};
        while (!stack.empty()) {
            const Item item = stack.back();
            stack.pop_back();
            split(item, stack);
        }
        return std::move(m_tree);
    }

private:
    Aabb range_box(uint32_t begin, uint32_t end) const {
        Aabb b;
        for (uint32_t k = begin; k < end; ++k) b.grow(m_box[m_tree.prim_ids[k]]);
        return b;
    }
    /// Orders references by centroid on `axis`, ties by primitive: every split is fully determined.
    auto by_centroid(int axis) const {
        return [this, axis](uint32_t x, uint32_t y) {
            return m_c2[x][axis] < m_c2[y][axis] || (m_c2[x][axis] == m_c2[y][axis] && x < y);
        };
    }
    bool fits_depth(const Item& item, uint32_t larger) const {
        return median_levels_needed(larger, m_c.max_leaf_size) + item.depth + 1 <= m_c.max_depth;
    }

    /// The best object partition by the SAH over every boundary of every axis: the references
    /// sorted by centroid, right boxes accumulated from the end, left boxes from the front.
    /// Returns the cost (sum of half area x references) and leaves the winning order in place.
    float sweep(const Item& item, int* best_axis, uint32_t* best_left) {
        const uint32_t n = item.end - item.begin;
        float best = std::numeric_limits<float>::infinity();
        m_right.resize(n);
        for (int a = 0; a < 3; ++a) {
            std::vector<uint32_t>& ids = m_sorted[a];
            ids.assign(m_tree.prim_ids.begin() + item.begin, m_tree.prim_ids.begin() + item.end);
            std::sort(ids.begin(), ids.end(), by_centroid(a));
            Aabb acc;
            for (uint32_t k = n; k-- > 1;) {
                acc.grow(m_box[ids[k]]);
                m_right[k] = acc.half_area();
            }
            acc = Aabb{};
            for (uint32_t k = 1; k < n; ++k) {
                acc.grow(m_box[ids[k - 1]]);
                const float cost = acc.half_area() * float(k) + m_right[k] * float(n - k);
                if (cost < best) best = cost, *best_axis = a, *best_left = k;
            }
        }
        return best;
    }

    /// The centroid median on the widest centroid axis.
    uint32_t median(const Item& item) {
        Aabb cb;
        for (uint32_t k = item.begin; k < item.end; ++k) cb.grow(m_c2[m_tree.prim_ids[k]]);
        uint32_t* ids = m_tree.prim_ids.data();
        const uint32_t mid = item.begin + (item.end - item.begin) / 2;
        std::nth_element(ids + item.begin, ids + mid, ids + item.end, by_centroid(cb.largest_axis()));
        return mid;
    }

    void split(const Item& item, std::vector<Item>& stack) {
        const uint32_t n = item.end - item.begin;
        BuildNode& node = m_tree.nodes[item.node];
        auto make_leaf = [&] { node.first = item.begin, node.count = n; };
        if (n == 1 || (!m_sah && n <= m_c.max_leaf_size)) return make_leaf();
        uint32_t mid = 0;
        // Near max_depth only median splits (or leaves), as in the binned builder.
        if (m_sah && item.depth + 8 < m_c.max_depth) {
            int axis = -1;
            uint32_t left = 0;
            const float cost = sweep(item, &axis, &left);
            const float area = node.box.half_area();
            const float split_cost = area > 0.0f ? m_c.traversal_cost + m_c.intersection_cost * cost / area
                                                 : std::numeric_limits<float>::infinity();
            if (n <= m_c.max_leaf_size && !(split_cost < m_c.intersection_cost * float(n))) return make_leaf();
            if (axis >= 0 && fits_depth(item, std::max(left, n - left))) {
                std::copy(m_sorted[axis].begin(), m_sorted[axis].end(), m_tree.prim_ids.begin() + item.begin);
                mid = item.begin + left;
            }
        } else if (m_sah && n <= m_c.max_leaf_size) {
            return make_leaf();
        }
        if (mid == 0) mid = median(item);
        // Children in an adjacent pair; the left one on top of the stack (leaves in left-first order).
        const uint32_t first = uint32_t(m_tree.nodes.size());
        m_tree.nodes.emplace_back();
        m_tree.nodes.emplace_back();
        m_tree.nodes[item.node].first = first;  // (after the growth: `node` may have moved)
        m_tree.nodes[item.node].count = 0;
        m_tree.nodes[first].box = range_box(item.begin, mid);
        m_tree.nodes[first + 1].box = range_box(mid, item.end);
        stack.push_back(Item{first + 1, mid, item.end, item.depth + 1});
        stack.push_back(Item{first, item.begin, mid, item.depth + 1});
    }

    BuildConfig m_c;
    bool m_sah;
    std::vector<Aabb> m_box;
    std::vector<Vec3> m_c2;  ///< twice the box centres
    BuildTree m_tree;
    std::vector<uint32_t> m_sorted[3];
    std::vector<float> m_right;
};

void validate(const std::vector<Triangle>& triangles, const BuildConfig& c) {
    require(!triangles.empty(), "scene has no triangles");
    require(c.max_leaf_size >= 1, "BuildConfig.max_leaf_size must be at least 1");
    require(c.max_depth >= 1 && c.max_depth <= kMaxSupportedDepth,
            "BuildConfig.max_depth must be in 1.." + std::to_string(kMaxSupportedDepth));
    require(c.traversal_cost >= 0.0f && c.intersection_cost > 0.0f,
            "BuildConfig.traversal_cost must be >= 0 and intersection_cost > 0");
    require(triangles.size() < (size_t(1) << 31), "build_bvh: too many triangles (>= 2^31)");
    const uint32_t need = median_levels_needed(uint32_t(triangles.size()), c.max_leaf_size);
    require(need <= c.max_depth, "BuildConfig.max_depth = " + std::to_string(c.max_depth) + " cannot hold " +
                                     std::to_string(triangles.size()) + " triangles (needs " + std::to_string(need) + ")");
}

}  // namespace sweep_detail

BuildTree build_sweep_sah(const std::vector<Triangle>& triangles, const BuildConfig& config) {
    sweep_detail::validate(triangles, config);
    return sweep_detail::ObjectBuilder(triangles, config, true).build();
}

BuildTree build_median(const std::vector<Triangle>& triangles, const BuildConfig& config) {
    sweep_detail::validate(triangles, config);
    return sweep_detail::ObjectBuilder(triangles, config, false).build();
}

}  // namespace rtsim
