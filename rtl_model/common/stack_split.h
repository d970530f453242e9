#pragma once
// Where a ray's traversal stack entries are in the model: on chip, or spilled to memory (the
// newest entries on chip). The step-demand function (rtl_model/traversal/step_demand.h) moves
// entries between the two as the ray's stack grows and shrinks; the ray carries the split with it
// (through the ray buffer too).
#include <cstdint>

namespace rtsim {

struct StackSplit {
    uint32_t local = 0;    ///< entries held on chip
    uint32_t spilled = 0;  ///< entries in memory, in spill slots 0 .. spilled - 1
};

}  // namespace rtsim
