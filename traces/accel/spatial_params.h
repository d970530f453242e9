#pragma once
// The root cell of the space-partitioning structures (kd-tree, BIH, octree): the box their cells
// subdivide, in the image's params as {"bounds": [[lo x, y, z], [hi x, y, z]]} (floats, exact in
// the JSON). A traversal unit holds it in registers; the first step clips the ray against it.
#include <string>

#include <nlohmann/json.hpp>

#include "traces/common/aabb.h"
#include "traces/scene/scene.h"

namespace rtsim {

nlohmann::json root_cell_json(const Aabb& bounds);
/// Reads and checks the root cell; throws rtsim::Error naming `where` and the field: missing, not
/// 3 + 3 finite numbers, or lo > hi on an axis.
Aabb root_cell_from_json(const nlohmann::json& params, const std::string& where);

/// True when the triangle lies in a face plane of the cell: its part there has area on both sides
/// of the face and may be listed on either (the invariant checks of the kd-tree and octree).
inline bool triangle_in_cell_face(const Triangle& t, const Aabb& cell) {
    for (int a = 0; a < 3; ++a)
        if (t.v0[a] == t.v1[a] && t.v1[a] == t.v2[a] && (t.v0[a] == cell.lo[a] || t.v0[a] == cell.hi[a])) return true;
    return false;
}

}  // namespace rtsim
