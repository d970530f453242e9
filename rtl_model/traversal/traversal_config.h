#pragma once
// Configuration of the traversal units.
#include <cstdint>

#include "rtl_model/common/choice.h"

namespace rtsim {

/// Execution models of traversal units (rtl_model/traversal/unit_registry.cpp builds each).
enum class UnitModel : uint8_t { mimd = 0 };
inline constexpr Choices<UnitModel, 1> kUnitModelChoices{{"mimd"}};

struct TraversalConfig {
    UnitModel model = UnitModel::mimd;  ///< how a unit runs its rays (unit_registry.h)
    uint32_t units = 8;              ///< traversal units
    uint32_t ray_contexts = 16;      ///< rays in flight per unit, each advancing independently
    uint32_t stack_entries = 8;      ///< on-chip traversal stack entries per ray; deeper entries spill
    uint32_t stack_entry_bytes = 0;  ///< bytes per stack entry; 0: the structure's (8 for a BVH, 12 for a kd-tree, ...)
    uint32_t issue_cycles = 1;       ///< cycles the unit's scheduler needs per traversal step

    template <class V>
    void visit(V& v) {
        v.choice("model", model, kUnitModelChoices, "Execution model of the traversal units: mimd (each ray context steps on its own, TRaX/STRaTA-style)");
        v.field("units", units, "units", "Traversal units", 1, 4096);
        v.field("ray_contexts", ray_contexts, "rays", "Ray contexts per unit (rays in flight)", 1, 4096);
        v.field("stack_entries", stack_entries, "entries", "On-chip stack entries per ray; overflow spills to memory", 1, 64);
        v.field("stack_entry_bytes", stack_entry_bytes, "bytes", "Bytes per stack entry (on-chip stack and spill traffic); 0: the structure's own (a BVH's 8: node and entry distance; a kd-tree's or BIH's 12; an octree's 32), resolved from the trace", 0, 64);
        v.field("issue_cycles", issue_cycles, "cycles", "Scheduler cycles per traversal step of one unit", 1, 100);
    }
};

}  // namespace rtsim
