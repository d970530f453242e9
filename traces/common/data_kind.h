#pragma once
// What a byte in the accelerator's memory is: every region of an acceleration-structure image
// and every region the model adds (rays, hits, stacks, ray-buffer overflow) has one kind, and
// caches and DRAM count bytes and hit rates per kind (docs/stats.md).
#include <cstdint>

namespace rtsim {

/// Values appear in stats and trace descriptors by name only; append new kinds at the end.
enum class DataKind : uint8_t {
    node = 0,        ///< interior nodes of a tree (BVH, kd-tree, BIH, octree)
    triangle = 1,    ///< triangles (HwTriangle, 48 bytes)
    ray = 2,         ///< ray records read when a ray starts
    hit = 3,         ///< hit records written when a ray ends
    stack = 4,       ///< traversal stack entries spilled from the on-chip stack
    ray_buffer = 5,  ///< ray states overflowing the treelet ray buffer
    prim_ref = 6,    ///< primitive references (index lists of grids and other spatial structures)
    cell = 7,        ///< grid cells
    instance = 8,    ///< instance records (transforms) of two-level structures
};
constexpr int kDataKindCount = 9;

/// "node", "triangle", ...
const char* data_kind_name(DataKind kind);
/// Parses a name of data_kind_name; false if unknown.
bool parse_data_kind(const char* name, DataKind* kind);

}  // namespace rtsim
