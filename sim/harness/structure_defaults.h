#pragma once
// What a run takes from the trace's acceleration structure rather than from the machine's config
// (docs/accel.md, "What the model takes from the structure"): the traversal stack's entry size
// (traversal.stack_entry_bytes = 0, the default, means the structure's: a BVH's 8 bytes, a
// kd-tree's 12, an octree's 32), and the mailbox its steppers use.
#include "sim/harness/simulate.h"
#include "traces/accel/accel.h"

namespace rtsim {

/// The options with traversal.stack_entry_bytes resolved from the trace's structure descriptor
/// when it is 0 (traces written before structures recorded it: 8). config.resolved.json then
/// holds the resolved value. Throws rtsim::Error naming the trace if it cannot be read.
SimOptions with_structure_defaults(const SimOptions& options);

/// Gives the structure's steppers the configured mailbox (mailbox.entries per ray).
inline void apply_mailbox(Accel& accel, const SimConfig& config) { accel.set_mailbox(config.mailbox.entries); }

/// Gives the structure's steppers the configured short stack (traversal.stack_overflow =
/// restart_trail: traversal.stack_entries entries). Throws rtsim::Error naming the field when the
/// trace's structure has no short-stack walk.
void apply_short_stack(Accel& accel, const SimConfig& config);

/// Gives the structure's steppers the configured reduced-precision box test
/// (traversal.box_precision_bits). Throws rtsim::Error naming the field when the trace's
/// structure cannot count its extra walk.
void apply_box_precision(Accel& accel, const SimConfig& config);

}  // namespace rtsim
