#pragma once
// What a byte in the accelerator's memory is: every region of an acceleration-structure image
// and every region the model adds (rays, hits, stacks, ray-buffer overflow) has one kind, and
// caches and DRAM count bytes and hit rates per kind (docs/stats.md).
#include <array>
#include <cstdint>

#include "traces/common/work_counts.h"

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
    texture = 9,     ///< texels read by hit shaders (the shading block's texture caches)
};
constexpr int kDataKindCount = 10;

/// A kind's name and what its accesses happen per: once per ray (ray records, hit records) or
/// once per unit of one work counter of the ray (a node or stack access per step, a triangle per
/// triangle test, ...). The analytic level scales a sample's accesses of each kind to the whole
/// trace by that counter (docs/fidelity.md, "The analytic level").
struct DataKindInfo {
    const char* name;
    bool per_ray;
    WorkField per_work;  ///< when not per_ray
};
inline constexpr std::array<DataKindInfo, kDataKindCount> kDataKinds{{
    {"node", false, WorkField::steps},
    {"triangle", false, WorkField::tri_tests},
    {"ray", true, WorkField::steps},
    {"hit", true, WorkField::steps},
    {"stack", false, WorkField::steps},
    {"ray_buffer", false, WorkField::steps},
    {"prim_ref", false, WorkField::refs},
    {"cell", false, WorkField::cell_steps},
    {"instance", false, WorkField::transforms},
    {"texture", true, WorkField::steps},
}};

/// "node", "triangle", ...
const char* data_kind_name(DataKind kind);
/// Parses a name of data_kind_name; false if unknown.
bool parse_data_kind(const char* name, DataKind* kind);

}  // namespace rtsim
