#pragma once
// What a run asks of a structure's steppers beyond the ray (docs/accel.md, "Step options"): the
// traversal techniques the model's units and the analytic level run, handed by value to
// Accel::make_stepper() and Accel::trace(), so no run changes a structure shared by others. The
// run's resolution step (sim/resolve/resolve.h) fills it from the config, once, after matching
// each technique against the structure's capabilities (capabilities.h); a structure ignores an
// option its capabilities do not offer.
#include <cstdint>

namespace rtsim {

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

    /// True when a structure's fused reference loop walks as its steppers do: no short stack or
    /// reduced-precision walk whose extra work only a stepper counts.
    bool fused_loop_walks_alike() const { return short_stack_entries == 0 && box_precision_bits == 0; }
};

}  // namespace rtsim
