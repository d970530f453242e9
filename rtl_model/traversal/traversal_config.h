#pragma once
// Configuration of the traversal units.
#include <cstdint>

#include "rtl_model/common/choice.h"

namespace rtsim {

/// Execution models of traversal units (rtl_model/traversal/unit_registry.cpp builds each).
enum class UnitModel : uint8_t { mimd = 0, simt = 1, packet = 2 };
inline constexpr Choices<UnitModel, 3> kUnitModelChoices{{"mimd", "simt", "packet"}};

/// Which operation kind a SIMT warp runs next (Aila & Laine 2009, "Understanding the efficiency
/// of ray traversal on GPUs", section 2): while_while keeps the kind it ran while any lane still
/// needs it (the inner loops of while-while traversal), if_if takes the next kind any lane needs
/// in turn each warp step (one step of each branch per loop iteration).
enum class SimtPolicy : uint8_t { while_while = 0, if_if = 1 };
inline constexpr Choices<SimtPolicy, 2> kSimtPolicyChoices{{"while_while", "if_if"}};

/// When a SIMT lane whose ray finished gets a new one: at its warp's next step (lane: persistent
/// threads that fetch work as they finish), or only once every lane of its warp has finished
/// (warp: the whole warp retires and is relaunched).
enum class SimtRefill : uint8_t { lane = 0, warp = 1 };
inline constexpr Choices<SimtRefill, 2> kSimtRefillChoices{{"lane", "warp"}};

/// What a push onto a full on-chip stack does: spill (the oldest entry is written to memory and
/// read back when needed) or restart_trail (a short stack: the oldest entry is dropped, and an
/// empty stack with dropped entries restarts at the root, guided by a restart trail; Laine 2010,
/// Vaidyanathan, Woop & Benthin 2019; traces/accel/short_stack.h). A restart without a trail is
/// not offered: a BVH's boxes overlap, so a restart from the root with only the current t_max
/// would visit finished leaves again (it is sound for kd-trees, Foley & Sugerman 2005).
enum class StackOverflow : uint8_t { spill = 0, restart_trail = 1 };
inline constexpr Choices<StackOverflow, 2> kStackOverflowChoices{{"spill", "restart_trail"}};

struct TraversalConfig {
    UnitModel model = UnitModel::mimd;  ///< how a unit runs its rays (unit_registry.h)
    uint32_t units = 8;              ///< traversal units
    uint32_t ray_contexts = 16;      ///< rays in flight per unit, each advancing independently
    uint32_t stack_entries = 8;      ///< on-chip traversal stack entries per ray; deeper entries spill
    uint32_t stack_entry_bytes = 0;  ///< bytes per stack entry; 0: the structure's (8 for a BVH, 12 for a kd-tree, ...)
    StackOverflow stack_overflow = StackOverflow::spill;  ///< a push onto a full on-chip stack: spill or drop and restart
    uint32_t box_precision_bits = 0;  ///< box tests' mantissa bits; 0: fp32 (docs/accel.md, "Reduced-precision box tests")
    uint32_t issue_cycles = 1;       ///< cycles the unit's scheduler needs per traversal step
    uint32_t lanes = 8;              ///< simt: rays per warp, stepping in lock-step; packet: rays per packet
    SimtPolicy simt_policy = SimtPolicy::while_while;  ///< simt: which operation kind a warp runs next
    SimtRefill simt_refill = SimtRefill::lane;         ///< simt: when a finished lane takes a new ray
    /// packet: the hybrid's threshold (Benthin et al. 2012): a packet whose active rays at a node
    /// are fewer than this fraction of its rays splits into single rays; 0: never
    double packet_split_below = 0.0;

    /// simt: warps per unit; packet: packets per unit (its ray contexts grouped `lanes` at a time).
    uint32_t warps() const { return lanes ? ray_contexts / lanes : 0; }

    template <class V>
    void visit(V& v) {
        v.choice("model", model, kUnitModelChoices, "Execution model of the traversal units: mimd (each ray context steps on its own, TRaX/STRaTA-style), simt (warps of `lanes` ray contexts in lock-step, GPU-style), packet (packets of `lanes` rays sharing one traversal stack, Wald et al. 2001; binary BVH only)");
        v.field("units", units, "units", "Traversal units", 1, 4096);
        v.field("ray_contexts", ray_contexts, "rays", "Ray contexts per unit (rays in flight)", 1, 4096);
        v.field("stack_entries", stack_entries, "entries", "On-chip stack entries per ray; overflow spills to memory", 1, 64);
        v.field("stack_entry_bytes", stack_entry_bytes, "bytes", "Bytes per stack entry (on-chip stack and spill traffic); 0: the structure's own (a BVH's 8: node and entry distance; a kd-tree's or BIH's 12; an octree's 32), resolved from the trace", 0, 64);
        v.choice("stack_overflow", stack_overflow, kStackOverflowChoices, "A push onto a full on-chip stack: spill (the oldest entry goes to memory and is read back) or restart_trail (a short stack: the oldest entry is dropped; an empty stack with dropped entries restarts at the root along a restart trail, Laine 2010; single-level BVH traces: bvh2, the wide and compressed BVHs)");
        v.field("box_precision_bits", box_precision_bits, "bits", "Explicit mantissa bits of a reduced-precision, conservative box pipeline (Keely 2014; Vaidyanathan et al. 2016): boxes, differences and slab distances rounded outward, so it accepts every box fp32 does and some more, whose subtrees are walked as extra work (hits unchanged); 0: fp32 (23 bits). Single-level BVH traces: bvh2, the wide and compressed BVHs", 0, 22);
        v.field("issue_cycles", issue_cycles, "cycles", "Scheduler cycles per traversal step of one unit", 1, 100);
        v.field("lanes", lanes, "rays", "simt: rays per warp in lock-step; packet: rays per packet; ray_contexts must be a multiple (warps or packets = ray_contexts / lanes)", 4, 64);
        v.choice("simt_policy", simt_policy, kSimtPolicyChoices, "simt: while_while (a warp keeps its operation kind while any lane needs it) or if_if (kinds in turn each warp step), Aila & Laine 2009");
        v.choice("simt_refill", simt_refill, kSimtRefillChoices, "simt: lane (a finished lane takes a new ray at its warp's next step) or warp (only when every lane of the warp has finished)");
        v.field("packet_split_below", packet_split_below, "fraction", "packet: a packet whose active rays at a node are fewer than this fraction of its rays splits, its rays finishing alone one after the other (Benthin et al. 2012's hybrid); 0: never", 0.0, 1.0);
    }
};

}  // namespace rtsim
