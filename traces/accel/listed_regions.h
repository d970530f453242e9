#pragma once
// The regions of a structure whose cells or leaves list their triangles by reference (grid,
// kd-tree, octree; docs/accel.md): its cells or nodes, the 4-byte reference lists and the
// triangles, checked and opened in one place so that every such structure fails alike on a
// malformed image.
#include <algorithm>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "traces/accel/accel_image.h"
#include "traces/accel/leaf_blocks.h"
#include "traces/accel/ref_list.h"
#include "traces/accel/spatial_params.h"
#include "traces/common/aabb.h"
#include "traces/common/error.h"

namespace rtsim {

/// What a listing structure's image holds besides its own region's records.
struct ListedRegions {
    const Region* cells = nullptr;  ///< the structure's own region ("nodes" or "cells")
    RefListView list;
    uint64_t ref_count = 0, triangle_count = 0;
};

/// Checks that `image` holds region `cells_name` of `cell_bytes`-byte records of kind
/// `cells_kind`, "prim_refs" of 4-byte references and the triangles. Throws rtsim::Error naming
/// `source` and `structure` ("kdtree", ...).
void check_listed_regions(const AccelImage& image, const std::string& structure, const std::string& cells_name,
                          DataKind cells_kind, uint32_t cell_bytes, const std::string& source);

/// check_listed_regions, then opens the triangles into `triangles`.
ListedRegions open_listed_regions(const AccelImage& image, TriangleStore& triangles,
                                  const std::string& structure, const std::string& cells_name,
                                  DataKind cells_kind, uint32_t cell_bytes, const std::string& source);

/// Where a tree of listing leaves (kd-tree, octree) lives: arrays and their addresses in the
/// memory image, and its root cell.
template <class Node>
struct ListedTreeView {
    const Node* nodes = nullptr;
    RefListView list;
    uint64_t node_count = 0, ref_count = 0, triangle_count = 0;
    uint64_t node_base = 0;  ///< address of node 0
    Aabb bounds;             ///< the root cell (the image's params)
};

/// open_listed_regions for a tree of `Node` records in region "nodes", with its root cell.
template <class Node>
ListedTreeView<Node> open_listed_tree(const AccelImage& image, TriangleStore& triangles,
                                      const std::string& structure, const std::string& source) {
    const ListedRegions r = open_listed_regions(image, triangles, structure, "nodes", DataKind::node,
                                                uint32_t(sizeof(Node)), source);
    ListedTreeView<Node> v;
    v.nodes = r.cells->records<Node>();
    v.node_count = r.cells->count;
    v.node_base = r.cells->base;
    v.list = r.list;
    v.ref_count = r.ref_count;
    v.triangle_count = r.triangle_count;
    v.bounds = root_cell_from_json(image.params, source + ": " + structure + " params");
    return v;
}

/// The checks every listing structure's validation shares, failing with "source: structure: what".
/// Messages are built only on failure: these run over every cell and reference of every trace.
class ListedChecks {
public:
    ListedChecks(const std::string& source, const std::string& structure)
        : m_prefix(source + ": " + structure + ": ") {}

    [[noreturn]] void fail(const std::string& what) const { throw Error(m_prefix + what); }
    /// `owner`'s ("node 3", "cell 3") list [first, first + count) lies inside prim_refs.
    void list_in_range(const char* owner_kind, uint64_t owner, uint64_t first, uint64_t count,
                       uint64_t ref_count) const {
        if (first + count > ref_count)
            fail(std::string(owner_kind) + " " + std::to_string(owner) + " lists prim_refs " +
                 std::to_string(first) + ".." + std::to_string(first + count - 1) + " of " +
                 std::to_string(ref_count));
    }
    /// Every reference names a triangle.
    void refs_name_triangles(const RefListView& list, uint64_t ref_count, uint64_t triangle_count) const {
        for (uint64_t r = 0; r < ref_count; ++r)
            if (list.refs[r] >= triangle_count)
                fail("prim_refs entry " + std::to_string(r) + " names triangle " +
                     std::to_string(list.refs[r]) + " of " + std::to_string(triangle_count));
    }

private:
    std::string m_prefix;
};

/// "0000ff00": a word as 8 hex digits.
inline std::string hex_word(uint32_t w) {
    static const char* digits = "0123456789abcdef";
    std::string s(8, '0');
    for (int k = 7; k >= 0; --k, w >>= 4) s[size_t(k)] = digits[w & 15u];
    return s;
}

/// Validates a tree of listing leaves whose children come after their parent, in one forward
/// pass: its size, each node reachable once, each leaf's list, each child's index and depth (at
/// most `max_depth` levels below the root, else the message `too_deep()`), then the references. Each node's cell
/// is carried down: `interior(i, node, cell, add_child)` checks interior node i against its cell
/// and calls add_child(k, child_cell) for each child. Returns the deepest level.
template <class Node, class TooDeep, class Interior>
uint32_t validate_listed_tree(const ListedTreeView<Node>& v, const ListedChecks& check, uint32_t max_depth,
                              TooDeep too_deep, Interior interior) {
    auto node_name = [](uint64_t i) { return "node " + std::to_string(i); };
    if (v.node_count == 0) check.fail("no nodes");
    if (v.node_count > Node::kMaxIndex || v.ref_count >= (1ull << 32) || v.triangle_count >= (1ull << 32))
        check.fail("more than 2^" + std::to_string(Node::kIndexBits) + " nodes or 2^32 references or triangles");
    std::vector<uint8_t> depth(v.node_count, 0), seen(v.node_count, 0);
    std::vector<Aabb> cell(v.node_count);
    seen[0] = 1;
    cell[0] = v.bounds;
    uint32_t deepest = 0;
    for (uint64_t i = 0; i < v.node_count; ++i) {
        const Node& n = v.nodes[i];
        if (!seen[i]) check.fail(node_name(i) + " is not reachable from the root");
        deepest = std::max<uint32_t>(deepest, depth[i]);
        if (n.leaf()) {
            // Reserved bits must be 0: a reader that trusts a field must check it, and a word
            // a later layout may give a meaning is not silently accepted with another.
            if (n.leaf_reserved() != 0)
                check.fail(node_name(i) + " is a leaf with non-zero reserved bits (0x" + hex_word(n.leaf_reserved()) + ")");
            check.list_in_range("node", i, n.first_ref(), n.ref_count(), v.ref_count);
            continue;
        }
        interior(i, n, cell[i], [&](uint64_t k, const Aabb& child_cell) {
            if (k <= i || k >= v.node_count)
                check.fail(node_name(i) + " names child " + std::to_string(k) +
                           (k < v.node_count ? " (not after it)" : " (out of range)"));
            if (seen[k]) check.fail(node_name(k) + " has two parents");
            if (depth[i] + 1u > max_depth) check.fail(too_deep());
            seen[k] = 1;
            depth[k] = uint8_t(depth[i] + 1);
            cell[k] = child_cell;
        });
    }
    check.refs_name_triangles(v.list, v.ref_count, v.triangle_count);
    return deepest;
}

}  // namespace rtsim
