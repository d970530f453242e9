// LBVH (lbvh_builder.h): Morton codes, one sort, splits at the highest differing bit.
#include "traces/bvh/lbvh_builder.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "traces/common/error.h"

namespace rtsim {
namespace {

/// Spreads the low `bits` bits of x three apart (bit i to bit 3i).
uint64_t spread(uint64_t x, uint32_t bits) {
    uint64_t out = 0;
    for (uint32_t i = 0; i < bits; ++i) out |= ((x >> i) & 1u) << (3 * i);
    return out;
}

struct Range {
    uint32_t node, first, count, depth;
};

/// Sorted (Morton code, triangle) pairs of the triangles' box centres, quantised within the
/// centres' bounds; `box` gets every triangle's box.
std::vector<std::pair<uint64_t, uint32_t>> morton_codes(const std::vector<Triangle>& triangles, uint32_t bits,
                                                        std::vector<Aabb>* box) {
    const size_t n = triangles.size();
    box->assign(n, Aabb{});
    Aabb centroids;
    for (size_t i = 0; i < n; ++i) {
        for (const Vec3& v : {triangles[i].v0, triangles[i].v1, triangles[i].v2}) {
            require(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z),
                    "build_lbvh: triangle " + std::to_string(i) + " has a non-finite vertex");
            (*box)[i].grow(v);
        }
        centroids.grow((*box)[i].center());
    }
    const double cells = double((1u << bits) - 1);
    std::vector<std::pair<uint64_t, uint32_t>> code(n);
    for (size_t i = 0; i < n; ++i) {
        const Vec3 c = (*box)[i].center();
        uint64_t key = 0;
        for (int a = 0; a < 3; ++a) {
            const double extent = double(centroids.hi[a]) - centroids.lo[a];
            const double q = extent > 0.0 ? (double(c[a]) - centroids.lo[a]) / extent * cells : 0.0;
            key |= spread(uint64_t(std::clamp(q, 0.0, cells)), bits) << (2 - a);
        }
        code[i] = {key, uint32_t(i)};
    }
    std::sort(code.begin(), code.end());
    return code;
}

/// The tree's topology over the sorted codes: a range splits where its highest differing bit
/// changes (or at its median), down to leaves of max_leaf_size.
void split_ranges(const std::vector<std::pair<uint64_t, uint32_t>>& code, const BuildConfig& config, BuildTree* tree) {
    tree->nodes.assign(1, BuildNode{});
    std::vector<Range> stack{{0, 0, uint32_t(code.size()), 0}};
    while (!stack.empty()) {
        const Range r = stack.back();
        stack.pop_back();
        if (r.count <= config.max_leaf_size) {
            tree->nodes[r.node].first = r.first;
            tree->nodes[r.node].count = r.count;
            continue;
        }
        // The highest bit in which the range's first and last codes differ splits it where it
        // changes from 0 to 1; equal codes, or too little depth left, split at the median.
        const uint64_t a = code[r.first].first, b = code[r.first + r.count - 1].first;
        uint32_t split = r.first + r.count / 2;
        const bool deep = r.depth + 1 + median_levels_needed(r.count, config.max_leaf_size) >= config.max_depth;
        if (a != b && !deep) {
            const uint64_t bit = uint64_t(1) << (63 - __builtin_clzll(a ^ b));
            split = uint32_t(std::partition_point(code.begin() + r.first, code.begin() + r.first + r.count,
                                                  [&](const auto& c) { return !(c.first & bit); }) - code.begin());
        }
        const uint32_t left = uint32_t(tree->nodes.size());
        tree->nodes.push_back(BuildNode{});
        tree->nodes.push_back(BuildNode{});
        tree->nodes[r.node].first = left;
        tree->nodes[r.node].count = 0;
        stack.push_back({left + 1, split, r.first + r.count - split, r.depth + 1});
        stack.push_back({left, r.first, split - r.first, r.depth + 1});
    }
}

}  // namespace

BuildTree build_lbvh(const std::vector<Triangle>& triangles, const BuildConfig& config, const LbvhConfig& lbvh) {
    const size_t n = triangles.size();
    require(n > 0, "scene has no triangles");
    require(n < (size_t(1) << 31), "build_lbvh: too many triangles (>= 2^31)");
    require(lbvh.morton_bits >= 1 && lbvh.morton_bits <= 21, "LbvhConfig.morton_bits must be in 1..21");
    require(config.max_leaf_size >= 1 && config.max_depth >= 16 && config.max_depth <= 64,
            "BuildConfig: max_leaf_size must be >= 1 and max_depth in 16..64 for LBVH");
    require(median_levels_needed(uint32_t(n), config.max_leaf_size) < config.max_depth,
            "BuildConfig.max_depth = " + std::to_string(config.max_depth) + " cannot hold " + std::to_string(n) +
                " triangles in leaves of " + std::to_string(config.max_leaf_size));
    std::vector<Aabb> box;
    const std::vector<std::pair<uint64_t, uint32_t>> code = morton_codes(triangles, lbvh.morton_bits, &box);
    BuildTree tree;
    tree.prim_ids.resize(n);
    for (size_t i = 0; i < n; ++i) tree.prim_ids[i] = code[i].second;
    split_ranges(code, config, &tree);
    // Boxes bottom up: children come after their parents.
    for (size_t i = tree.nodes.size(); i-- > 0;) {
        BuildNode& node = tree.nodes[i];
        node.box = Aabb{};
        if (node.is_leaf()) {
            for (uint32_t k = node.first; k < node.first + node.count; ++k) node.box.grow(box[tree.prim_ids[k]]);
        } else {
            node.box.grow(tree.nodes[node.first].box);
            node.box.grow(tree.nodes[node.first + 1].box);
        }
    }
    return tree;
}

}  // namespace rtsim
