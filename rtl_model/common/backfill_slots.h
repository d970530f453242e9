#pragma once
// N slots (a shared cache's MSHRs) that remember each slot's booked intervals, so a request
// stamped earlier than bookings already made takes an idle gap before them instead of queueing
// behind the future. A shared L2 is reached out of time order even when its issuers run in
// lock step: an L1 miss that waited for its own MSHR is forwarded at once, stamped with the
// cycle that MSHR frees. A free list of "free again at" times (MinTree) makes a request stamped
// earlier wait behind every such booking although the slot sits idle until then; on designs
// short of MSHRs at both levels that made the detailed level 11% slow against the slot rule
// (docs/fidelity.md, "Where designs starve or fill slowly").
//
// In time order (a request at or after every booking's start) the pick is the free list's: the
// slot free earliest, lowest index on a tie. Out of order a slot is taken where it has an idle
// gap of `expected` cycles (a miss's duration is known only once it has been served); a miss
// longer than its gap overlaps the next booking of its slot, as a calendar would let it.
#include <cstdint>
#include <vector>

#include "rtl_model/common/interfaces.h"
#include "rtl_model/common/min_tree.h"

namespace rtsim {

class BackfillSlots {
public:
    explicit BackfillSlots(uint32_t slots);

    struct Pick {
        uint32_t slot = 0;
        Cycle start = 0;  ///< the first cycle at or after the request's the slot takes it
    };
    /// The slot that can take a request at `time` soonest for `expected` cycles.
    Pick earliest(Cycle time, Cycle expected) const;
    /// `slot` is held over [start, end).
    void book(uint32_t slot, Cycle start, Cycle end);

private:
    struct Interval {
        Cycle start, end;
    };
    /// Intervals kept per slot (the latest by start): a request stamped before all of them is
    /// rarer than one in 10^5 on the traces measured, and then takes the slot's oldest gap.
    static constexpr size_t kKeep = 16;
    std::vector<std::vector<Interval>> m_booked;  ///< per slot, sorted by start
    std::vector<Cycle> m_last_end;                ///< per slot, the latest end booked
    MinTree m_free;                               ///< m_last_end, for the in-order pick
    Cycle m_latest_start = 0;                     ///< latest start booked on any slot
};

}  // namespace rtsim
