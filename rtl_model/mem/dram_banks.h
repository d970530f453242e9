#pragma once
// DRAM banks and row buffers (dram.model = "banks", at the approx and detailed levels): per channel `banks` banks, each
// with one row buffer, an open-page or close-page policy, and activate (tRCD), precharge (tRP)
// and column (tCAS) timing in core cycles, in front of the channel's data bus (bytes_per_cycle).
// Timing after JEDEC DDR command rules reduced to their first-order terms (Jacob, Ng & Wang,
// "Memory Systems", 2008, ch. 11-13), the way Ramulator's and DRAMSim's simple bank state
// machines do; docs/model.md has the address map and the hand-worked sequences the tests check.
//
// Per request at channel c, bank b, row r, arriving at cycle t (scheduler fcfs):
//   s   = the first cycle >= t at which the bank is idle long enough for the request; the row
//         state is that left by the bank's previous access in time
//   row hit      (open page, row r open):   column at s
//   row miss     (bank closed):             activate at s, column at s + tRCD
//   row conflict (another row open):        precharge at s, activate s + tRP, column s + tRP + tRCD
//   data: ceil(bytes / bytes_per_cycle) cycles on the bus, from the first free bus cycles at or
//   after column + tCAS; done = cycle after the last data cycle.
//   the bank is busy from s to column + burst cycles (open page; the row stays open), or to
//   column + burst + tRP with close page (auto-precharge: every access finds the bank closed).
// Second-order limits, each off at 0 (dram_config.h): tRAS delays a precharge (a conflict's, or a
// close page's auto-precharge) to at least tRAS after the row's activate; tRRD and tFAW delay an
// activate until no other activate of the channel is within tRRD of it and no window of tFAW
// cycles holds more than four (checked against the channel's last 32 activates, before and after
// it in time); an all-bank refresh every tREFI cycles occupies each bank of the channel for tRFC
// (an access that would overlap one starts after it, once: an access longer than the time between
// refreshes, outside any DDR part's timing, runs past the next) and closes every row. The gap a
// request takes must fit its whole delayed service. Not modelled: a row left open across a
// refresh owes no tRAS or tRP before it.
// Bank groups and turnaround, each off at 0 as well: bank b of a channel is in group
// b mod bank_groups; tRRD_L spaces two activates in one group (tRRD the others), tCCD_L two
// column commands in one group (other groups are spaced by their bursts on the data bus, tCCD_S);
// tWTR spaces a read's column command after the end of a write's data on the channel (tWTR_L,
// t_wtr_l, when both are in one bank group; tWTR_S, t_wtr, otherwise), tRTW a write's column
// command after a read's. A column command is delayed until each of these holds
// against the channel's last 32 column commands, before and after it in time, as activates are
// for tRRD and tFAW. A controller queue of queue_entries requests per channel: a request holds
// an entry from its arrival to its last data cycle, and one arriving at a full queue starts when
// an entry frees (BackfillSlots: a request stamped before bookings already made takes an entry
// idle long enough before them). Not modelled: write queues drained in batches, the command bus. FR-FCFS (scheduler frfcfs, open page): a request to a row that a
// booked access leaves open, and that the next booked access closes, is served right after the
// first (a row hit) instead of after the bank's last booking; the bookings it passes move back
// by as much as it overlaps them. Their times were already returned: they keep them (optimistic
// by moved_back_cycles in all; their bus cycles and commands stay where they were booked), but
// later requests see the bank as the reordered schedule leaves it.
// At detailed requests normally arrive in time order (units synchronise every cycle), and then
// this is first come, first served; at approx units run up to a quantum apart, so requests
// arrive out of order within a quantum and back-fill as below. Only the last 64 bookings per
// bank are kept: a request older than all of them starts at its own time with the row the
// forgotten bookings left open (optimistic; rare unless a bank is saturated for a whole quantum). A request stamped earlier than one already booked
// (a miss that waited for an MSHR is stamped in the future) takes an idle gap before it, the
// way a bandwidth calendar back-fills, instead of queueing behind the future; the row outcome
// of the later, already booked access is not revised.
// Pure C++ (no SystemC), owned by Dram.
#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "rtl_model/common/backfill_slots.h"
#include "rtl_model/common/calendar.h"
#include "rtl_model/mem/dram_config.h"

namespace rtsim {

struct DramAddress {
    uint32_t channel = 0;
    uint32_t bank = 0;
    uint32_t group = 0;  ///< bank group: bank mod bank_groups
    uint64_t row = 0;
    uint32_t column = 0;  ///< byte offset in the row
};

class DramBanks {
public:
    enum class RowResult : uint8_t { hit, miss, conflict };

    explicit DramBanks(const DramConfig& config);

    /// Address map: channel = (addr / interleave) mod channels; the channel-local address drops
    /// the channel bits; column = local mod row_bytes, bank = (local / row_bytes) mod banks,
    /// row = local / (row_bytes x banks). Consecutive lines of a row stay in one bank and row.
    DramAddress map(uint64_t addr) const;

    struct Timing {
        Cycle start = 0;   ///< cycle the bank started serving the request (>= arrival)
        Cycle column = 0;  ///< cycle of the column command
        Cycle done = 0;    ///< cycle after the last data cycle on the bus
        RowResult result = RowResult::miss;
        Cycle ras_wait = 0;      ///< cycles the precharge waited for tRAS
        Cycle activate_wait = 0; ///< cycles the activate waited for tRRD and tFAW
        Cycle refresh_wait = 0;  ///< cycles the start waited for a refresh
        Cycle column_wait = 0;   ///< cycles the column command waited for tCCD_L, tWTR, tRTW
        Cycle queue_wait = 0;    ///< cycles the request waited for an entry of a full queue
    };
    /// Serves one request of `bytes` bytes arriving at `time` (a write when `write`).
    Timing access(uint64_t addr, uint32_t bytes, Cycle time, bool write = false);

    uint64_t row_hits() const { return m_totals[0]; }
    uint64_t row_misses() const { return m_totals[1]; }
    uint64_t row_conflicts() const { return m_totals[2]; }
    /// {row_hits, row_misses, row_conflicts, row_hit_rate, page_policy, banks_per_channel,
    ///  row_bytes, by_bank: [{channel, bank, accesses, row_hits, row_misses, row_conflicts}]}
    nlohmann::json stats_json() const;

private:
    static constexpr uint64_t kClosed = ~0ull;
    static constexpr Cycle kNoActivate = ~Cycle(0);
    struct Booking {
        Cycle start;       ///< cycle the bank starts this access
        Cycle end;         ///< first idle cycle after it
        uint64_t row;      ///< row open after it (kClosed: precharged)
        Cycle activated = 0;  ///< activate of that row (tRAS counts from it)
    };
    /// The bank state an access finds: the row open, since when, and when the bank went idle.
    struct OpenRow {
        uint64_t row;
        Cycle activated;
        Cycle idle_since;
    };
    /// The bank's recent bookings sorted by start, in a ring (requests arrive nearly in time
    /// order, so a new booking goes at or near the end and the oldest is forgotten from the front).
    struct Bank {
        static constexpr uint32_t kKept = 64;        ///< bookings remembered
        static constexpr uint32_t kRing = 2 * kKept; ///< ring size (power of two, > kKept)
        Booking ring[kRing];
        uint32_t head = 0, size = 0;
        uint64_t base_row = kClosed;   ///< row open after the oldest forgotten access
        Cycle base_activated = 0, base_end = 0;
        uint64_t counts[3] = {};       ///< hits, misses, conflicts
        Booking& at(uint32_t i) { return ring[(head + i) & (kRing - 1)]; }
        /// Index of the first booking starting after `time` (size if none).
        uint32_t upper_bound(Cycle time);
        /// Inserts at index i (shifting later ones), then forgets the oldest beyond kKept.
        void insert(uint32_t i, const Booking& b);
    };
    /// FR-FCFS: the first place after `time` where the bank's bookings leave row a.row open and
    /// the next booking changes it; there `t` is a row hit booked (the bookings after it moved
    /// back as far as it overlaps them) and true. False if there is none (FCFS gives the same).
    bool row_hit_first(Bank& bank, const DramAddress& a, Cycle time, Cycle burst, bool write, Timing* t);
    /// The service of an access to `a` starting no earlier than `s` with the bank as `open`
    /// left it: its start (later past a refresh), row outcome, column command and end.
    Timing plan(const DramAddress& a, Cycle s, OpenRow open, Cycle burst, bool write, Cycle* end,
                Cycle* activate) const;
    /// The first cycle at or after `at` at which channel `c` may activate in `group` (tRRD, tRRD_L, tFAW).
    Cycle first_activate(uint32_t c, uint32_t group, Cycle at) const;
    void record_activate(uint32_t c, uint32_t group, Cycle at);
    /// The first cycle at or after `at` at which channel `c` may issue the column command of an
    /// access of `burst` bus cycles in `group` (tCCD_L, tWTR, tRTW).
    Cycle first_column(uint32_t c, uint32_t group, bool write, Cycle burst, Cycle at) const;
    void record_column(uint32_t c, uint32_t group, bool write, Cycle burst, Cycle at);
    struct Activate {
        Cycle at;
        uint32_t group;
    };
    struct Column {
        Cycle at;
        uint32_t group;
        bool write;
        Cycle burst;
    };
    DramConfig m_config;
    bool m_close_page;
    bool m_column_limits;  ///< any of tCCD_L, tWTR, tRTW set
    bool m_frfcfs;         ///< scheduler frfcfs with open pages
    std::vector<Bank> m_banks;          ///< channel-major: channel * banks + bank
    std::vector<SlotCalendar> m_buses;  ///< one data bus per channel: bytes_per_cycle per cycle
    std::vector<std::vector<Activate>> m_activates;  ///< per channel: its last activates, sorted
    std::vector<std::vector<Column>> m_columns;      ///< per channel: its last column commands, sorted
    std::vector<BackfillSlots> m_queues;  ///< per channel: its controller queue (queue_entries > 0)
    uint64_t m_totals[3] = {};
    Cycle m_ras_wait = 0, m_activate_wait = 0, m_refresh_wait = 0, m_column_wait = 0, m_queue_wait = 0;
    uint64_t m_queue_full = 0;  ///< requests that found their channel's queue full
    uint64_t m_hits_first = 0;  ///< FR-FCFS: row hits served ahead of a booked row change
    Cycle m_moved_back = 0;     ///< FR-FCFS: cycles the bookings they passed moved back, summed
};

}  // namespace rtsim
