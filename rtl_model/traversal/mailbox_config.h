#pragma once
// Configuration of the traversal units' mailboxes (docs/accel.md, "Mailboxes"): a small table per
// ray context of the primitives the ray has tested, so a primitive listed in several cells or
// leaves of a grid, kd-tree or octree is tested (and its triangle fetched) once per ray. The
// table travels with the ray (its state in the ray buffer grows by 4 bytes an entry).
#include <cstdint>

namespace rtsim {

struct MailboxConfig {
    uint32_t entries = 0;  ///< primitive ids remembered per ray context, first in first out; 0: no mailbox

    /// Bytes of one entry: a primitive id.
    static constexpr uint32_t kEntryBytes = 4;

    template <class V>
    void visit(V& v) {
        v.field("entries", entries, "entries",
                "Mailbox entries per ray context (primitives tested, FIFO); retests of a listed primitive are skipped "
                "in grids, kd-trees and octrees; 0: no mailbox",
                0, 64);
    }
};

}  // namespace rtsim
