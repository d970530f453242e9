#pragma once
// Stepper::stack_reads for the tree structures whose stack entries name a node or a leaf's
// triangles ({ref, count}: count 0 a node, else the leaf's first triangle and count): the binary
// and wide BVHs' steppers and packet steppers. Each entry's read is the fetch its step would plan.
#include <cstdint>

#include "traces/accel/leaf_blocks.h"
#include "traces/accel/step_plan.h"

namespace rtsim {

/// The reads of the top `max` entries of stack[0, size), top first: node `ref` of `node_bytes`
/// at `node_base`, or the leaf's triangles where `tri_at` says; returns how many it wrote.
template <class Entry>
uint32_t tree_stack_reads(const Entry* stack, int size, uint64_t node_base, uint32_t node_bytes,
                          const TriangleAddressing& tri_at, Fetch* out, uint32_t max) {
    uint32_t n = 0;
    for (int i = size - 1; i >= 0 && n < max; --i, ++n) {
        const Entry& e = stack[i];
        if (e.count == 0) {
            out[n] = Fetch{node_base + uint64_t(e.ref) * node_bytes, node_bytes, DataKind::node};
        } else {
            const TriangleAddressing::Span s = tri_at.span(e.ref, e.count);
            out[n] = Fetch{s.address, s.bytes, DataKind::triangle};
        }
    }
    return n;
}

}  // namespace rtsim
