#pragma once
// What a structure offers the techniques a run may ask for, declared as data beside its registry
// entry (registry.cpp) and read by the run's one resolution step (sim/resolve/resolve.h), which
// matches a unit kind's and the techniques' needs against it before anything is built. Python and
// sweeps read the same table by kind name (rtsim._core.accel_kinds()), so a spec is checked
// before any trace exists.
#include <cstdint>

#include <nlohmann/json.hpp>

namespace rtsim {

struct AccelCapabilities {
    /// A packet stepper and reference packet loop (Accel::make_packet_stepper): packet units.
    bool packet_kernel = false;
    /// A short stack with a restart trail (short_stack.h): traversal.stack_overflow=restart_trail.
    bool restart_trail = false;
    /// A conservative reduced-precision box walk (rp_boxes.h): traversal.box_precision_bits.
    bool reduced_precision_boxes = false;
    /// Its nodes store child boxes as 8-bit integers on a per-node grid, which an integer box
    /// pipeline tests directly (AQB8): traversal.quantized_boxes.
    bool quantized_boxes = false;
    /// Any-hit rays' child order at a node (StepOptions::anyhit_order): traversal.anyhit_order.
    bool anyhit_order = false;
    /// References that repeat along a ray, which its steppers look up in a mailbox (mailbox.h).
    bool mailbox = false;
    /// Its triangles may be stored as compressed leaf blocks (leaf_blocks.h).
    bool compressed_leaves = false;
    /// It may be the bottom level of a two-level structure (two_level.h).
    bool blas = false;
    /// It partitions itself into treelets or cell blocks (Accel::partition): treelet scheduling.
    bool treelet_partition = true;
    /// It is built from a binary build tree that can be refitted to moved geometry (refit.h):
    /// --frame-policy refit and adaptive.
    bool refit = false;
    /// Its steppers report the reads their stack entries would issue (Stepper::stack_reads):
    /// stack-driven prefetching, traversal.stack_prefetch.
    bool stack_addresses = false;
    /// Its builders bound primitives by their boxes and its leaves test whatever records they
    /// hold, so a scene's curved primitives (spheres, capsules) are stored and tested as such;
    /// kinds that clip triangles against planes (kd-tree, grid, octree, GK-BVH) refuse them.
    bool curved = false;
    /// Bytes of one traversal stack entry (Accel::stack_entry_bytes; 0: no stack).
    uint32_t stack_entry_bytes = 8;

    /// This, offering `flag` as well: capabilities read by name, never by position
    /// (`single_level(8).with(&AccelCapabilities::mailbox)`).
    AccelCapabilities with(bool AccelCapabilities::*flag) const {
        AccelCapabilities c = *this;
        c.*flag = true;
        return c;
    }

    nlohmann::json to_json() const {
        return {{"packet_kernel", packet_kernel},
                {"restart_trail", restart_trail},
                {"reduced_precision_boxes", reduced_precision_boxes},
                {"quantized_boxes", quantized_boxes},
                {"anyhit_order", anyhit_order},
                {"mailbox", mailbox},
                {"compressed_leaves", compressed_leaves},
                {"blas", blas},
                {"treelet_partition", treelet_partition},
                {"refit", refit},
                {"stack_addresses", stack_addresses},
                {"curved", curved},
                {"stack_entry_bytes", stack_entry_bytes}};
    }
};

/// A single-level kind's capabilities before its own: its stack entry, and compressed leaves
/// (every single-level kind's triangles may be stored as leaf blocks).
inline AccelCapabilities single_level(uint32_t stack_entry_bytes) {
    AccelCapabilities c;
    c.stack_entry_bytes = stack_entry_bytes;
    c.compressed_leaves = true;
    return c;
}

}  // namespace rtsim
