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
#include <cstddef>
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
    /// `slot` is held over [start, end) by a request stamped `time` (<= start).
    void book(uint32_t slot, Cycle time, Cycle start, Cycle end);

private:
    struct Interval {
        Cycle start, end;
    };
    /// How far behind the latest request's stamp a request may still be stamped: intervals that
    /// ended longer before it are dropped (a request stamped before a dropped one then starts
    /// after it: it waits rather than taking a slot that may be held). Every booking inside it is kept (a cap by count let a
    /// request stamped behind a deep queue of bookings take a slot already held: 16 units on 8
    /// L2 MSHRs held 40 at once); requests are stamped apart by an L1 MSHR wait, thousands of
    /// cycles at most.
    static constexpr Cycle kHorizon = Cycle(1) << 18;
    /// A slot's bookings, sorted by start, from `head` on (those before it were dropped; the
    /// vector is compacted when they are half of it: a flat array searches faster than a deque).
    struct Booked {
        std::vector<Interval> v;
        size_t head = 0;
        Cycle floor = 0;  ///< latest end of a dropped booking: a request stamped before it waits
    };
    std::vector<Booked> m_booked;
    std::vector<Cycle> m_last_end;                ///< per slot, the latest end booked
    MinTree m_free;                               ///< m_last_end, for the in-order pick
    Cycle m_latest_start = 0;                     ///< latest start booked on any slot
    Cycle m_latest_request = 0;                   ///< latest request stamp booked
    Cycle m_longest = 0;                          ///< longest interval booked (where a search starts)
};

}  // namespace rtsim
