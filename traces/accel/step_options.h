#pragma once
// What a run asks of a structure's steppers beyond the ray (docs/accel.md, "Step options"): the
// traversal techniques the model's units and the analytic level run, handed by value to
// Accel::make_stepper() and Accel::trace(), so no run changes a structure shared by others. The
// run's resolution step (sim/resolve/resolve.h) fills it from the config, once, after matching
// each technique against the structure's capabilities (capabilities.h); a structure ignores an
// option its capabilities do not offer.
#include <array>
#include <cstdint>
#include <string>

namespace rtsim {

/// Which hit child an any-hit (occlusion) ray visits first at a binary BVH node. Closest-hit rays
/// always go nearest first. Any order gives the same occlusion answer (hit or miss); only the
/// work to find an occluder and which occluder is found differ.
enum class AnyHitOrder : uint8_t {
    nearest = 0,      ///< nearer entry distance first (child 0 on ties): the closest-hit order
    largest_box = 1,  ///< larger child box surface area first: more likely to hold an occluder
    fixed = 2,        ///< child 0 first, no sort
};
/// Their names, in value order (the config's traversal.anyhit_order, rtsim trace --anyhit-order).
inline constexpr std::array<const char*, 3> kAnyHitOrderNames{{"nearest", "largest_box", "fixed"}};
/// True and *order set when `name` is one of kAnyHitOrderNames.
inline bool parse_anyhit_order(const std::string& name, AnyHitOrder* order) {
    for (size_t i = 0; i < kAnyHitOrderNames.size(); ++i)
        if (name == kAnyHitOrderNames[i]) {
            *order = AnyHitOrder(i);
            return true;
        }
    return false;
}

struct StepOptions {
    /// Primitive ids remembered per ray (mailbox.h; structures whose references repeat along a
    /// ray); 0: none. Hits never change; the mailbox's counts go to the model-only work fields.
    uint32_t mailbox_entries = 0;
    /// On-chip entries of a short stack with a restart trail (short_stack.h; Laine 2010); 0: a
    /// full stack. Hits and the reference work never change; restarts are model-only work.
    uint32_t short_stack_entries = 0;
    /// Mantissa bits of a conservative reduced-precision box test (rp_boxes.h); 0: fp32 alone.
    /// Hits and the reference work never change; the extra walk is model-only work.
    uint32_t box_precision_bits = 0;
    /// AQB8-style quantised box tests (wide_stepper.h; structures with quantised nodes): the
    /// integer test's extra walk, in the same model-only rp_* work fields. Hits and the
    /// reference work never change.
    bool quantized_box_tests = false;
    /// Child order of any-hit rays (binary BVH steppers); hit/miss never changes, the occluder
    /// found and the work may. The fused loops walk nearest first, so other orders use a stepper.
    AnyHitOrder anyhit_order = AnyHitOrder::nearest;

    /// The order the trace's any-hit rays were traced in (its reference work): nearest first
    /// unless traced with `rtsim trace --anyhit-order` (the structure's stats say so).
    AnyHitOrder traced_anyhit_order = AnyHitOrder::nearest;

    /// Any-hit rays walk in another child order than the trace's: the hit checker checks their
    /// occlusion alone (HitChecker::set_reordered_anyhit).
    bool reorders_anyhit() const { return anyhit_order != traced_anyhit_order; }

    /// The options a reference packet loop walks with (Accel::trace_packet): the any-hit order,
    /// which changes the walk; the others only add model-only work, which the reference leaves out.
    StepOptions reference_walk() const {
        StepOptions o;
        o.anyhit_order = anyhit_order;
        return o;
    }

    /// True when a structure's fused reference loop walks as its steppers do: no short stack or
    /// reduced-precision walk whose extra work only a stepper counts, and any-hit rays nearest first.
    bool fused_loop_walks_alike() const {
        return short_stack_entries == 0 && box_precision_bits == 0 && !quantized_box_tests &&
               anyhit_order == AnyHitOrder::nearest;
    }
};

}  // namespace rtsim
