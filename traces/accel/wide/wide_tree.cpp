// Wide build trees: splitting oversized binary leaves, octant slot assignment, invariants
// (wide_tree.h). The collapses themselves are in collapse.cpp.
#include <algorithm>
#include <array>
#include <string>
#include <tuple>

#include "traces/accel/wide/wide_tree.h"
#include "traces/common/error.h"

namespace rtsim {
namespace {

Aabb triangle_box(const Triangle& t) {
    Aabb b;
    b.grow(t.v0);
    b.grow(t.v1);
    b.grow(t.v2);
    return b;
}

Aabb clip(const Aabb& a, const Aabb& b) { return Aabb{glm::max(a.lo, b.lo), glm::min(a.hi, b.hi)}; }

/// Splits split_large_leaves makes in a leaf of `count` triangles (halving until <= leaf_max).
uint32_t splits_needed(uint32_t count, uint32_t leaf_max) {
    return count <= leaf_max ? 0 : 1 + splits_needed(count / 2, leaf_max) + splits_needed(count - count / 2, leaf_max);
}

}  // namespace

BuildTree split_large_leaves(const BuildTree& in, const std::vector<Triangle>& triangles, uint32_t leaf_max) {
    return split_large_leaves(BuildTree(in), triangles, leaf_max);
}

BuildTree split_large_leaves(BuildTree&& in, const std::vector<Triangle>& triangles, uint32_t leaf_max) {
    require(leaf_max >= 1, "split_large_leaves: leaf_max must be at least 1");
    // Nodes the splits add (two per split; a piece is split again while too large), so the
    // node array grows once.
    size_t added = 0;
    for (const BuildNode& b : in.nodes)
        if (b.is_leaf()) added += 2 * size_t(splits_needed(b.count, leaf_max));
    BuildTree out = std::move(in);
    out.nodes.reserve(out.nodes.size() + added);
    // Nodes appended while splitting are visited too: a piece may still be too large.
    for (size_t n = 0; n < out.nodes.size(); ++n) {
        const BuildNode leaf = out.nodes[n];
        if (!leaf.is_leaf() || leaf.count <= leaf_max) continue;
        auto begin = out.prim_ids.begin() + leaf.first, end = begin + leaf.count;
        Aabb centroids;
        for (auto it = begin; it != end; ++it) {
            require(*it < triangles.size(), "split_large_leaves: primitive id out of range");
            centroids.grow(triangle_box(triangles[*it]).center());
        }
        const int axis = centroids.largest_axis();
        const uint32_t half = leaf.count / 2;
        // Object median; ties by primitive id, so the split is deterministic.
        std::nth_element(begin, begin + half, end, [&](uint32_t a, uint32_t b) {
            const float ca = triangle_box(triangles[a]).center()[axis], cb = triangle_box(triangles[b]).center()[axis];
            return ca < cb || (ca == cb && a < b);
        });
        const uint32_t first_child = uint32_t(out.nodes.size());
        for (uint32_t side = 0; side < 2; ++side) {
            BuildNode piece;
            piece.first = leaf.first + (side ? half : 0);
            piece.count = side ? leaf.count - half : half;
            for (uint32_t k = piece.first; k < piece.first + piece.count; ++k)
                piece.box.grow(triangle_box(triangles[out.prim_ids[k]]));
            piece.box = clip(piece.box, leaf.box);
            out.nodes.push_back(piece);
        }
        out.nodes[n].first = first_child;
        out.nodes[n].count = 0;
    }
    return out;
}

void assign_octant_slots(WideBuildTree& tree) {
    require(tree.width == 8, "octant slots need 8-wide nodes");
    for (WideBuildNode& node : tree.nodes) {
        const Vec3 centre = node.box.center();
        std::vector<std::tuple<float, uint32_t, uint32_t>> pairs;  // (cost, child, slot)
        for (uint32_t c = 0; c < node.count; ++c) {
            const Vec3 offset = node.child[c].box.center() - centre;
            for (uint32_t s = 0; s < 8; ++s) {
                const Vec3 dir((s & 1) ? -1.0f : 1.0f, (s & 2) ? -1.0f : 1.0f, (s & 4) ? -1.0f : 1.0f);
                pairs.emplace_back(glm::dot(offset, dir), c, s);
            }
        }
        std::sort(pairs.begin(), pairs.end());
        uint32_t child_done = 0, slot_used = 0;
        for (const auto& [cost, c, s] : pairs) {
            if ((child_done >> c & 1u) || (slot_used >> s & 1u)) continue;
            node.slot[c] = uint8_t(s);
            child_done |= 1u << c;
            slot_used |= 1u << s;
        }
    }
}

namespace {
/// Children of a node in slot order (child indices sorted by their slot).
int by_slot(const WideBuildNode& n, uint32_t out[kMaxWideWidth]) {
    int count = 0;
    for (uint32_t s = 0; s < kMaxWideWidth; ++s)
        for (uint32_t i = 0; i < n.count; ++i)
            if (n.slot[i] == s) out[count++] = i;
    return count;
}
}  // namespace

WideOrder wide_order(const WideBuildTree& tree) {
    WideOrder o;
    o.index.assign(tree.nodes.size(), 0);
    o.leaf_first.assign(tree.nodes.size() * kMaxWideWidth, 0);
    o.stored.reserve(tree.nodes.size());
    o.prims.reserve(tree.prims.size());
    o.stored.push_back(0);
    std::vector<uint32_t> stack{0};  // build nodes whose children are still to be placed
    while (!stack.empty()) {
        const uint32_t b = stack.back();
        stack.pop_back();
        const WideBuildNode& n = tree.nodes[b];
        uint32_t slots[kMaxWideWidth];
        const int count = by_slot(n, slots);
        for (int k = 0; k < count; ++k) {
            const WideBuildChild& c = n.child[slots[k]];
            if (c.is_leaf()) {
                o.leaf_first[size_t(b) * kMaxWideWidth + slots[k]] = uint32_t(o.prims.size());
                o.leaf_starts.push_back(uint32_t(o.prims.size()));
                o.prims.insert(o.prims.end(), tree.prims.begin() + c.first, tree.prims.begin() + c.first + c.count);
            } else {
                o.index[c.node] = uint32_t(o.stored.size());
                o.stored.push_back(c.node);
            }
        }
        for (int k = count - 1; k >= 0; --k)  // the first slot's block is laid out next
            if (!n.child[slots[k]].is_leaf()) stack.push_back(n.child[slots[k]].node);
    }
    return o;
}

WideShape wide_shape(const WideBuildTree& tree) {
    WideShape s;
    std::vector<uint32_t> depth(tree.nodes.size(), 0);
    uint64_t tris = 0, children = 0;
    for (uint32_t i = 0; i < tree.nodes.size(); ++i) {
        const WideBuildNode& n = tree.nodes[i];
        children += n.count;
        for (uint32_t k = 0; k < n.count; ++k) {
            const WideBuildChild& c = n.child[k];
            if (!c.is_leaf()) {
                depth[c.node] = depth[i] + 1;
                continue;
            }
            ++s.leaves;
            tris += c.count;
            s.max_leaf_size = std::max(s.max_leaf_size, c.count);
            s.max_depth = std::max(s.max_depth, depth[i] + 1);
        }
    }
    s.avg_leaf_size = s.leaves ? double(tris) / s.leaves : 0.0;
    s.avg_children = tree.nodes.empty() ? 0.0 : double(children) / double(tree.nodes.size());
    return s;
}

void check_wide_tree(const WideBuildTree& tree, uint32_t leaf_max) {
    auto fail = [](uint32_t n, const std::string& what) {
        throw Error("wide tree: node " + std::to_string(n) + ": " + what);
    };
    require(!tree.nodes.empty(), "wide tree: no nodes");
    std::vector<uint8_t> seen(tree.nodes.size(), 0);
    for (uint32_t n = 0; n < tree.nodes.size(); ++n) {
        const WideBuildNode& node = tree.nodes[n];
        if (n > 0 && !seen[n]) fail(n, "unreachable from the root");
        if (node.count == 0 || node.count > uint32_t(tree.width)) fail(n, "has " + std::to_string(node.count) + " children");
        uint32_t slots = 0;
        for (uint32_t i = 0; i < node.count; ++i) {
            const WideBuildChild& c = node.child[i];
            if (!node.box.contains(c.box)) fail(n, "child " + std::to_string(i) + " box outside the node box");
            if (node.slot[i] >= tree.width || (slots >> node.slot[i] & 1u)) fail(n, "slots are not distinct");
            slots |= 1u << node.slot[i];
            if (c.is_leaf()) {
                if (c.count > leaf_max) fail(n, "leaf of " + std::to_string(c.count) + " triangles");
                if (uint64_t(c.first) + c.count > tree.prims.size()) fail(n, "leaf prims out of range");
                continue;
            }
            if (c.node <= n || c.node >= tree.nodes.size()) fail(n, "interior child not after its parent");
            if (seen[c.node]) fail(n, "node " + std::to_string(c.node) + " has two parents");
            seen[c.node] = 1;
            if (!(c.box.lo == tree.nodes[c.node].box.lo && c.box.hi == tree.nodes[c.node].box.hi))
                fail(n, "child " + std::to_string(i) + " box differs from its node's box");
        }
    }
}

}  // namespace rtsim
