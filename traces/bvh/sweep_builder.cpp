// The full-sweep SAH, local-ray-termination and equal-count builders (sweep_builder.h).
#include "traces/bvh/sweep_builder.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <glm/glm.hpp>

#include "traces/common/error.h"

namespace rtsim {
namespace sweep_detail {

/// The traversal stack's size (kTraversalStackSize): deeper trees could overflow it.
constexpr uint32_t kMaxSupportedDepth = 64;

struct Item {
    uint32_t node, begin, end, depth;
};

enum class Cost { median, sah, termination };

class ObjectBuilder {
public:
    ObjectBuilder(const std::vector<Triangle>& tris, const BuildConfig& c, Cost cost)
        : m_c(c), m_sah(cost != Cost::median), m_termination(cost == Cost::termination) {
        const size_t n = tris.size();
        m_box.resize(n);
        m_c2.resize(n);
        m_area.resize(n);
        for (size_t i = 0; i < n; ++i) {
            for (const Vec3& v : {tris[i].v0, tris[i].v1, tris[i].v2}) {
                require(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z),
                        "build_bvh: triangle " + std::to_string(i) + " has a non-finite vertex");
                m_box[i].grow(v);
            }
            m_c2[i] = m_box[i].lo + m_box[i].hi;
            m_area[i] = 0.5f * glm::length(glm::cross(tris[i].v1 - tris[i].v0, tris[i].v2 - tris[i].v0));
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
    /// With local ray termination the cost of a split is lowered by what the rays that enter
    /// both children save when they stop in the one they visit first (termination_saving).
    float sweep(const Item& item, float parent_area, int* best_axis, uint32_t* best_left) {
        const uint32_t n = item.end - item.begin;
        float best = std::numeric_limits<float>::infinity();
        m_right.resize(n);
        m_right_tris.resize(n);
        m_right_lo.resize(n);
        for (int a = 0; a < 3; ++a) {
            std::vector<uint32_t>& ids = m_sorted[a];
            ids.assign(m_tree.prim_ids.begin() + item.begin, m_tree.prim_ids.begin() + item.end);
            std::sort(ids.begin(), ids.end(), by_centroid(a));
            Aabb acc;
            float tris = 0;
            for (uint32_t k = n; k-- > 1;) {
                acc.grow(m_box[ids[k]]);
                tris += m_area[ids[k]];
                m_right[k] = acc.half_area();
                m_right_tris[k] = tris;
                m_right_lo[k] = acc.lo[a];
            }
            acc = Aabb{};
            tris = 0;
            for (uint32_t k = 1; k < n; ++k) {
                acc.grow(m_box[ids[k - 1]]);
                tris += m_area[ids[k - 1]];
                const float left = acc.half_area();
                float cost = left * float(k) + m_right[k] * float(n - k);
                // Only children apart along the axis: a ray through both then leaves the first
                    // before it enters the second, so a hit in the first culls the second (with
                    // overlapping boxes the second's entry may come before the hit).
                if (m_termination && acc.hi[a] <= m_right_lo[k])
                    cost -= termination_saving(parent_area, left, tris, float(k), m_right[k], m_right_tris[k], float(n - k));
                if (cost < best) best = cost, *best_axis = a, *best_left = k;
            }
        }
        return best;
    }

    /// Local ray termination (after Moulin & Dutre's use of it in SAH-style builds): a ray that
    /// enters both children visits one first and, if it hits a triangle there, need not visit
    /// the other. Of the rays through the parent (half area A), at least (A_l + A_r - A) / A enter
    /// both (exact for adjacent boxes: they cross the shared face); each child is first half of
    /// the time; a ray through a box of half area h hits a flat triangle of area t inside it with
    /// probability t / h (Cauchy: a convex body's surface over the box's; a triangle has two
    /// sides), so a child stops it with probability alpha = min(1, sum of t / h). The saving is
    /// those rays' share of the other child's tests, in the sweep's units (half area x references).
    static float termination_saving(float parent, float left, float left_tris, float nl, float right,
                                    float right_tris, float nr) {
        const float both = std::max(0.0f, left + right - parent);
        if (both <= 0.0f) return 0.0f;
        const float alpha_l = left > 0.0f ? std::min(1.0f, left_tris / left) : 0.0f;
        const float alpha_r = right > 0.0f ? std::min(1.0f, right_tris / right) : 0.0f;
        return 0.5f * both * (alpha_l * nr + alpha_r * nl);
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
            const float area = node.box.half_area();
            const float cost = sweep(item, area, &axis, &left);
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
    bool m_sah, m_termination;
    std::vector<Aabb> m_box;
    std::vector<Vec3> m_c2;  ///< twice the box centres
    std::vector<float> m_area;  ///< each triangle's area
    BuildTree m_tree;
    std::vector<uint32_t> m_sorted[3];
    std::vector<float> m_right, m_right_tris, m_right_lo;  ///< per boundary: the right side's box half area, triangle area, low bound on the axis
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
    return sweep_detail::ObjectBuilder(triangles, config, sweep_detail::Cost::sah).build();
}

BuildTree build_sweep_termination(const std::vector<Triangle>& triangles, const BuildConfig& config) {
    sweep_detail::validate(triangles, config);
    return sweep_detail::ObjectBuilder(triangles, config, sweep_detail::Cost::termination).build();
}

BuildTree build_median(const std::vector<Triangle>& triangles, const BuildConfig& config) {
    sweep_detail::validate(triangles, config);
    return sweep_detail::ObjectBuilder(triangles, config, sweep_detail::Cost::median).build();
}

}  // namespace rtsim
