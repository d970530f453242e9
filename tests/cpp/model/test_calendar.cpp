// InOrderResource and BandwidthCalendar: the reservation primitives every shared block uses;
// MinTree, the earliest of per-slot times (event queues, MSHRs).
#include <gtest/gtest.h>

#include <map>

#include "rtl_model/common/backfill_slots.h"
#include "rtl_model/common/calendar.h"
#include "rtl_model/common/min_tree.h"
#include "traces/common/error.h"

namespace rtsim {
namespace {

TEST(InOrderResource, SerialisesRequestsInTimeOrder) {
    InOrderResource r;
    EXPECT_EQ(r.reserve(0, 3), 0u);   // free: starts at once
    EXPECT_EQ(r.reserve(1, 3), 3u);   // busy until 3: waits
    EXPECT_EQ(r.reserve(10, 1), 10u); // idle gap: starts at its own time
    EXPECT_EQ(r.reserve(10, 2), 11u);
    EXPECT_EQ(r.busy_cycles(), 9u);
    EXPECT_EQ(r.free_at(), 13u);
}

TEST(BandwidthCalendar, RespectsCapacityPerWindow) {
    // 4 units per window of 10 cycles; 40 requests of one unit at cycle 0.
    BandwidthCalendar cal(4, 10);
    std::map<Cycle, int> per_window;
    Cycle last = 0;
    for (int i = 0; i < 40; ++i) {
        Cycle start = cal.reserve(0, 1);
        EXPECT_GE(start, last) << "requests at the same time are served in arrival order";
        last = start;
        ++per_window[start / 10];
    }
    ASSERT_EQ(per_window.size(), 10u) << "40 units at 4 per window take exactly 10 windows";
    for (const auto& [window, n] : per_window) EXPECT_EQ(n, 4) << "window " << window;
    // Within a window, service starts in proportion to what the window already serves.
    BandwidthCalendar fluid(4, 10);
    EXPECT_EQ(fluid.reserve(0, 1), 0u);
    EXPECT_EQ(fluid.reserve(0, 1), 2u);
    EXPECT_EQ(fluid.reserve(0, 2), 5u);
    EXPECT_EQ(fluid.reserve(0, 1), 10u);  // window 0 is full
    EXPECT_EQ(fluid.total_reserved(), 5u);
}

TEST(BandwidthCalendar, LaterRequestsDoNotBlockEarlierOnes) {
    BandwidthCalendar cal(4, 10);
    // A unit that ran ahead fills the window at cycle 1000 ...
    for (int i = 0; i < 4; ++i) EXPECT_EQ(cal.reserve(1000, 1) / 10, 100u);
    // ... and one that lags behind still gets the free window at cycle 5 (a next-free-cycle
    // counter would serialise it behind cycle 1000).
    EXPECT_EQ(cal.reserve(5, 1), 5u);
    // The full window at 1000 pushes the next request there to the following window.
    EXPECT_EQ(cal.reserve(1000, 1), 1010u);
}

TEST(BandwidthCalendar, SaturatesAtCapacity) {
    // Offered load of 3 units per cycle against a capacity of 8 per 4 cycles (2 per cycle).
    BandwidthCalendar cal(8, 4);
    Cycle last = 0;
    const int n = 30000;
    for (int i = 0; i < n; ++i) last = std::max(last, cal.reserve(Cycle(i / 3), 1));
    const double rate = double(n) / double(last + 1);
    EXPECT_NEAR(rate, 2.0, 0.02);
    // Below capacity nothing queues: 1 unit per cycle starts on time.
    BandwidthCalendar light(8, 4);
    for (Cycle t = 0; t < 1000; ++t) EXPECT_EQ(light.reserve(t, 1), t);
}

TEST(BandwidthCalendar, OversizedRequestSpillsIntoFollowingWindows) {
    // 100 units at 16 per 8-cycle window: windows 0-5 full, window 6 holds 4. The resource never
    // serves more than its capacity, however large one request is.
    BandwidthCalendar cal(16, 8);
    EXPECT_EQ(cal.reserve(0, 100), 0u);
    EXPECT_EQ(cal.reserve(0, 1), 6u * 8 + 4 * 8 / 16);
    EXPECT_EQ(cal.total_reserved(), 101u);
}

TEST(BandwidthCalendar, RejectsZeroCapacityOrWindow) {
    EXPECT_THROW(BandwidthCalendar(0, 4), Error);
    EXPECT_THROW(BandwidthCalendar(4, 0), Error);
}

TEST(BackfillSlots, InTimeOrderTheSlotFreeEarliest) {
    // 4 MSHRs: 4 misses of 100 cycles at cycle 0 each take one; a fifth waits for the first to
    // free, on the lowest slot among equals, as a free list would have it.
    BackfillSlots mshrs(4);
    for (uint32_t i = 0; i < 4; ++i) {
        const BackfillSlots::Pick p = mshrs.earliest(0, 100);
        EXPECT_EQ(p.start, 0u) << i;
        EXPECT_EQ(p.slot, i);
        mshrs.book(p.slot, 0, 0, 100 + i);
    }
    const BackfillSlots::Pick fifth = mshrs.earliest(10, 100);
    EXPECT_EQ(fifth.slot, 0u);
    EXPECT_EQ(fifth.start, 100u);
}

TEST(BackfillSlots, NeverHoldsMoreThanItsSlotsOutOfOrder) {
    // 20,000 misses of 150 cycles on 8 MSHRs, stamped up to 5,000 cycles behind the latest (a
    // deep queue: far more bookings a slot than any cap by count would keep), offered 9x faster
    // than the MSHRs serve them and again just below their rate. Whatever the order, no cycle
    // sees more than 8 held; saturated, the misses take 20,000 x 150 / 8 cycles.
    for (const Cycle step : {Cycle(2), Cycle(18)}) {
        BackfillSlots mshrs(8);
        std::map<Cycle, int> delta;  // +1 at a start, -1 at an end
        uint64_t state = 12345;
        Cycle front = 0, last = 0;
        for (int n = 0; n < 20000; ++n) {
            state = state * 6364136223846793005ull + 1442695040888963407ull;
            front += step;
            const Cycle back = (state >> 33) % 5000;
            const Cycle time = front > back ? front - back : 0;
            const BackfillSlots::Pick p = mshrs.earliest(time, 150);
            ASSERT_GE(p.start, time);
            mshrs.book(p.slot, time, p.start, p.start + 150);
            ++delta[p.start];
            --delta[p.start + 150];
            last = std::max(last, p.start + 150);
        }
        int held = 0, most = 0;
        for (const auto& [cycle, d] : delta) most = std::max(most, held += d);
        EXPECT_LE(most, 8) << step;
        EXPECT_GE(double(last), 20000.0 * 150 / 8) << step;
        if (step == 2) {
            EXPECT_NEAR(double(last), 20000.0 * 150 / 8, 20000.0 * 150 / 8 * 0.02);
        }
    }
}

TEST(BackfillSlots, ARequestStampedBeforeDroppedBookingsWaits) {
    // A booking that ended a horizon before the latest stamp is dropped; a request stamped before
    // its end starts after it (it may be held then) instead of taking the slot at its stamp.
    BackfillSlots one(1);
    one.book(0, 0, 0, 100);
    const Cycle late = Cycle(1) << 19;
    one.book(0, late, late, late + 100);  // drops [0, 100)
    EXPECT_EQ(one.earliest(50, 10).start, 100u);
    EXPECT_EQ(one.earliest(200, 10).start, 200u);  // idle after it, before the later booking
}

TEST(BackfillSlots, AnEarlierStampedRequestTakesTheIdleGapBeforeLaterBookings) {
    // One MSHR booked over [1000, 1100) by a request stamped ahead (an L1 miss that waited for
    // its MSHR): a request stamped 0 takes the slot at once when its miss fits before 1000, and
    // after 1100 when it does not. A free list made it wait until 1100 either way.
    BackfillSlots one(1);
    one.book(0, 1000, 1000, 1100);
    EXPECT_EQ(one.earliest(0, 100).start, 0u);
    EXPECT_EQ(one.earliest(950, 100).start, 1100u);
    one.book(0, 0, 0, 100);
    EXPECT_EQ(one.earliest(50, 100).start, 100u);   // the gap [100, 1000) after its booking
    EXPECT_EQ(one.earliest(50, 900).start, 100u);   // exactly long enough
    EXPECT_EQ(one.earliest(50, 901).start, 1100u);  // a cycle too short
    // Of two slots, the one idle soonest; back to the in-order rule once past every start.
    BackfillSlots two(2);
    two.book(0, 500, 500, 600);
    two.book(1, 200, 200, 300);
    EXPECT_EQ(two.earliest(250, 50).slot, 0u);
    EXPECT_EQ(two.earliest(250, 50).start, 250u);
    EXPECT_EQ(two.earliest(700, 50).slot, 1u);  // free since 300, slot 0 since 600: the lower end
    EXPECT_EQ(two.earliest(700, 50).start, 700u);
}

TEST(MinTree, RunnerUpIsTheEarliestSlotBesideTheTop) {
    MinTree t(6);
    EXPECT_EQ(t.runner_up(), MinTree::kMaxSlots);  // empty
    t.set(4, 30);
    EXPECT_EQ(t.top(), 4u);
    EXPECT_EQ(t.runner_up(), MinTree::kMaxSlots);  // only one slot set
    t.set(1, 50), t.set(5, 40), t.set(2, 30);
    EXPECT_EQ(t.top(), 2u);        // ties to the lower slot
    EXPECT_EQ(t.runner_up(), 4u);  // the tie's other slot, in another subtree
    t.set(2, 60);
    EXPECT_EQ(t.top(), 4u);
    EXPECT_EQ(t.runner_up(), 5u);  // 40, before slot 1 (50) and slot 2 (60)
    // Against a scan, over a changing set of times (ties to the lower slot).
    MinTree r(6);
    Cycle times[6];
    for (Cycle& c : times) c = MinTree::kNever;
    uint64_t seed = 7;
    for (int i = 0; i < 200; ++i) {
        seed = seed * 6364136223846793005ull + 1442695040888963407ull;
        const uint32_t slot = uint32_t(seed >> 60) % 6;
        times[slot] = (seed >> 20) % 16;
        r.set(slot, times[slot]);
        uint32_t second = MinTree::kMaxSlots;
        for (uint32_t s = 0; s < 6; ++s)
            if (s != r.top() && times[s] != MinTree::kNever && (second == MinTree::kMaxSlots || times[s] < times[second])) second = s;
        EXPECT_EQ(r.runner_up(), second);
    }
}

}  // namespace
}  // namespace rtsim
