#pragma once
// The regions of a structure whose cells or leaves list their triangles by reference (grid,
// kd-tree, octree; docs/accel.md): its cells or nodes, the 4-byte reference lists and the
// triangles, checked and opened in one place so that every such structure fails alike on a
// malformed image.
#include <cstdint>
#include <string>

#include "traces/accel/accel_image.h"
#include "traces/accel/leaf_blocks.h"
#include "traces/accel/ref_list.h"
#include "traces/accel/spatial_params.h"
#include "traces/common/aabb.h"

namespace rtsim {

/// What a listing structure's image holds besides its own region's records.
struct ListedRegions {
    const Region* cells = nullptr;  ///< the structure's own region ("nodes" or "cells")
    RefListView list;
    uint64_t ref_count = 0, triangle_count = 0;
};

/// Checks that `image` holds region `cells_name` of `cell_bytes`-byte records of kind
/// `cells_kind`, "prim_refs" of 4-byte references and the triangles, then opens the triangles
/// into `triangles`. Throws rtsim::Error naming `source` and `structure` ("kdtree", ...).
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

}  // namespace rtsim
