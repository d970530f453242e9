#pragma once
// Configuration of the traversal units: what every unit kind has (units, contexts, the stack);
// each kind's own fields are its section (traversal.<kind>, declared in its folder: unit_kind.h).
#include <cstdint>
#include <string>
#include <vector>

#include "rtl_model/common/choice.h"
#include "rtl_model/traversal/unit_kind.h"
#include "traces/accel/step_options.h"

namespace rtsim {

/// What a push onto a full on-chip stack does: spill (the oldest entry is written to memory and
/// read back when needed) or restart_trail (a short stack: the oldest entry is dropped, and an
/// empty stack with dropped entries restarts at the root, guided by a restart trail; Laine 2010,
/// Vaidyanathan, Woop & Benthin 2019; traces/accel/short_stack.h). A restart without a trail is
/// not offered: a BVH's boxes overlap, so a restart from the root with only the current t_max
/// would visit finished leaves again (it is sound for kd-trees, Foley & Sugerman 2005).
enum class StackOverflow : uint8_t { spill = 0, restart_trail = 1 };
inline constexpr Choices<StackOverflow, 2> kStackOverflowChoices{{"spill", "restart_trail"}};

/// Which hit child an any-hit (shadow) ray visits first at a node (traces/accel/step_options.h):
/// nearest (entry distance, the closest-hit order), largest_box (larger surface area first: more
/// likely to hold an occluder) or fixed (child 0 first, no sort). Hit/miss never changes.
inline constexpr Choices<AnyHitOrder, 3> kAnyHitOrderChoices{kAnyHitOrderNames};

/// Ray contexts per unit when traversal.ray_contexts is 0 and each context runs alone.
inline constexpr uint32_t kDefaultRayContexts = 16;

struct TraversalConfig {
    std::string model = "mimd";      ///< the unit kind (unit_kind.h): how a unit runs its rays
    uint32_t units = 8;              ///< traversal units
    uint32_t ray_contexts = 0;       ///< rays in flight per unit; 0: derived (contexts())
    uint32_t stack_entries = 8;      ///< on-chip traversal stack entries per ray; deeper entries spill
    uint32_t stack_entry_bytes = 0;  ///< bytes per stack entry; 0: the structure's (8 for a BVH, 12 for a kd-tree, ...)
    StackOverflow stack_overflow = StackOverflow::spill;  ///< a push onto a full on-chip stack: spill or drop and restart
    uint32_t box_precision_bits = 0;  ///< box tests' mantissa bits; 0: fp32 (docs/accel.md, "Reduced-precision box tests")
    bool quantized_boxes = false;     ///< AQB8-style integer box pipeline on quantised nodes
    AnyHitOrder anyhit_order = AnyHitOrder::nearest;  ///< any-hit rays' child order at a node
    uint32_t issue_cycles = 1;       ///< cycles the unit's scheduler needs per traversal step
    uint32_t stack_prefetch = 0;     ///< stack entries prefetched on consecutive pops (TTP); 0: off
    /// Each unit kind's own section (traversal.simt, traversal.packet, ...): the kinds' fields.
    UnitSections kinds;

    /// The unit kind `model` names (throws naming traversal.model when none).
    const UnitKind& kind() const { return unit_kind(model); }
    /// The chosen kind's section as C.
    template <class C>
    const C& kind_config() const {
        return kinds.of<C>(model);
    }
    /// Rays that step together on the chosen kind (1 for MIMD contexts; a warp's lanes; a packet).
    uint32_t group_size() const { return kind().group_size(*this); }
    /// Groups per unit (warps, packets; contexts for MIMD): contexts() / group_size().
    uint32_t groups() const { return contexts() / group_size(); }
    /// The ray contexts of a resolved config: ray_contexts, or when 0 the default 16 rounded up to
    /// a whole number of the kind's groups (one 32-lane warp for simt with 32 lanes).
    uint32_t contexts() const {
        if (ray_contexts) return ray_contexts;
        const uint32_t g = group_size();
        return (kDefaultRayContexts + g - 1) / g * g;
    }

    template <class V>
    void visit(V& v) {
        std::vector<const char*> kind_names;
        for (const UnitKind* k : unit_kinds()) kind_names.push_back(k->name.c_str());
        v.choice_of("model", model, kind_names, "Execution model of the traversal units (each kind registers itself: rtsim capabilities lists them): mimd (each ray context steps on its own, TRaX/STRaTA-style), simt (warps of traversal.simt.lanes ray contexts in lock-step, GPU-style), packet (packets of traversal.packet.lanes rays sharing one traversal stack, Wald et al. 2001)");
        v.field("units", units, "units", "Traversal units", 1, 4096);
        v.field("ray_contexts", ray_contexts, "rays", "Ray contexts per unit (rays in flight); 0: derived, 16 rounded up to a whole number of the unit kind's warps or packets (the summary lists it under 'derived')", 0, 4096);
        v.field("stack_entries", stack_entries, "entries", "On-chip stack entries per ray; overflow spills to memory", 1, 64);
        v.field("stack_entry_bytes", stack_entry_bytes, "bytes", "Bytes per stack entry (on-chip stack and spill traffic); 0: the structure's own (a BVH's 8: node and entry distance; a kd-tree's or BIH's 12; an octree's 32), resolved from the trace", 0, 64);
        v.choice("stack_overflow", stack_overflow, kStackOverflowChoices, "A push onto a full on-chip stack: spill (the oldest entry goes to memory and is read back) or restart_trail (a short stack: the oldest entry is dropped; an empty stack with dropped entries restarts at the root along a restart trail, Laine 2010; structures with a restart trail: rtsim capabilities)");
        v.field("box_precision_bits", box_precision_bits, "bits", "Explicit mantissa bits of a reduced-precision, conservative box pipeline (Keely 2014; Vaidyanathan et al. 2016): boxes, differences and slab distances rounded outward, so it accepts every box fp32 does and some more, whose subtrees are walked as extra work (hits unchanged); 0: fp32 (23 bits). Structures with a reduced-precision walk: rtsim capabilities", 0, 22);
        v.flag("quantized_boxes", quantized_boxes, "AQB8-style quantised box pipeline (Huang, Yang & Yeh, ISCA 2025): the box pipelines test a compressed node's 8-bit child boxes in integer arithmetic after quantising the ray into the node's grid (no dequantiser), conservative by one grid cell, whose extra subtrees are walked as extra work (hits unchanged), and are priced at integer widths. Structures with quantised nodes (cwbvh6, cwbvh8): rtsim capabilities");
        v.choice("anyhit_order", anyhit_order, kAnyHitOrderChoices, "Which hit child an any-hit (shadow) ray visits first at a node: nearest (entry distance, as closest-hit rays), largest_box (the larger child box surface area first: more likely to hold an occluder) or fixed (child 0 first, no sort). Occlusion (hit or miss) never changes; the occluder found and the work may. Structures with the setting: rtsim capabilities");
        v.field("stack_prefetch", stack_prefetch, "entries", "Stack-driven prefetching (TTP, Tozlu, Naithani & Zhou 2026): when a ray's step pushes nothing and pops its traversal stack (the paper's second pop in a row: going back up the tree), the lines of the top this-many stack entries, whose addresses the stack holds, are prefetched into the unit's L1; 0: off. Structures whose stacks hold addresses: rtsim capabilities", 0, 8);
        v.field("issue_cycles", issue_cycles, "cycles", "Scheduler cycles per traversal step of one unit", 1, 100);
        kinds.visit(v);
    }
};

}  // namespace rtsim
