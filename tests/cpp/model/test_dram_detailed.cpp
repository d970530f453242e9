// DRAM banks and row buffers (dram.model = banks): activate/precharge/column timing and
// the data bus, against hand-worked sequences (docs/model.md, "Banks and row buffers"), and the
// ring of bookings against the std::map model it replaced, on random out-of-order streams.
#include <gtest/gtest.h>

#include <map>
#include <random>
#include <tuple>

#include "model_test_util.h"
#include "rtl_model/mem/dram.h"
#include "rtl_model/mem/dram_banks.h"

namespace rtsim {
namespace {

using test::TestKernel;
using Row = DramBanks::RowResult;

/// One channel, 2 banks of 1 KiB rows, 16 B/cycle (a 64-byte burst is 4 cycles), tRCD 10,
/// tRP 8, tCAS 6, latency 100 (front end = 100 - tRCD - tCAS = 84). Address map with one
/// channel: column = addr mod 1024, bank = (addr / 1024) mod 2, row = addr / 2048.
DramConfig small(const char* policy = "open") {
    DramConfig c;
    c.channels = 1;
    c.bytes_per_cycle = 16;
    c.latency = 100;
    c.interleave_bytes = 256;
    c.banks = 2;
    c.row_bytes = 1024;
    EXPECT_TRUE(kPagePolicyChoices.parse(policy, &c.page_policy));
    c.t_rcd = 10;
    c.t_rp = 8;
    c.t_cas = 6;
    return c;
}

struct Step {
    uint64_t addr;
    Cycle arrive;
    Row result;
    Cycle column;  ///< column command
    Cycle done;    ///< cycle after the last data cycle on the bus
    Cycle ready;   ///< what Dram::access returns: done + front end (84)
};

void run_table(const DramConfig& config, const std::vector<Step>& table) {
    TestKernel kernel;
    DramBanks banks(config);
    Dram dram("dram", config);
    for (size_t i = 0; i < table.size(); ++i) {
        const Step& s = table[i];
        DramBanks::Timing t = banks.access(s.addr, 64, s.arrive);
        EXPECT_EQ(int(t.result), int(s.result)) << "step " << i;
        EXPECT_EQ(t.column, s.column) << "step " << i;
        EXPECT_EQ(t.done, s.done) << "step " << i;
        EXPECT_EQ(dram.access({s.addr, 64, false, DataKind::node, s.arrive}), s.ready) << "step " << i;
    }
}

TEST(DramDetailed, AddressMapSplitsChannelBankRowColumn) {
    DramConfig c = small();
    c.channels = 2;  // channel = (addr / 256) mod 2; the channel-local address drops that bit
    DramBanks banks(c);
    DramAddress a = banks.map(0x300 + 5);  // granule 3: channel 1, local granule 1 -> local 0x105
    EXPECT_EQ(a.channel, 1u);
    EXPECT_EQ(a.column, 0x105u);
    EXPECT_EQ(a.bank, 0u);
    EXPECT_EQ(a.row, 0u);
    a = banks.map(2 * 2048 + 1024);  // local (2*2048+1024)/2 = 2560: column 512, bank 0, row 1
    EXPECT_EQ(a.channel, 0u);
    EXPECT_EQ(a.column, 512u);
    EXPECT_EQ(a.bank, 0u);
    EXPECT_EQ(a.row, 1u);
    a = banks.map(2 * 1024 + 256);  // granule 8 -> channel 0, local 1024: bank 1, row 0
    EXPECT_EQ(a.bank, 1u);
    EXPECT_EQ(a.row, 0u);
}

TEST(DramDetailed, OpenPageRowHitMissConflictSequence) {
    // Worked by hand (docs/model.md has the same table).
    run_table(small(), {
        // addr  arrive  result          column  done  ready
        {0,      0,      Row::miss,      10,     20,   104},  // bank 0 closed: activate, +tRCD; data 16..19
        {64,     0,      Row::hit,       14,     24,   108},  // row 0 open; bank busy until 10+4; data 20..23
        {2048,   30,     Row::conflict,  48,     58,   142},  // bank 0 row 1: precharge 30, activate 38, column 48
        {1024,   30,     Row::miss,      40,     50,   134},  // bank 1 in parallel; data 46..49 fits before 54
        {2112,   100,    Row::hit,       100,    110,  194},  // row 1 still open
        {2176,   200,    Row::hit,       200,    210,  294},  // bank 0 row 1: data 206..209
        {1152,   200,    Row::hit,       200,    214,  298},  // bank 1 row 0: data ready 206, bus busy: 210..213
    });
}

TEST(DramDetailed, FrFcfsServesARowHitAheadOfABookedConflict) {
    // Worked by hand (docs/model.md): request 3 finds row 0 open until cycle 14 and request 2's
    // conflict booked after it; FR-FCFS serves it there as a hit and moves request 2 back by its
    // burst (request 2 keeps the times it was given: moved_back_cycles counts them).
    DramConfig c = small();
    ASSERT_TRUE(kDramSchedulerChoices.parse("frfcfs", &c.scheduler));
    run_table(c, {
        // addr  arrive  result          column  done  ready
        {0,      0,      Row::miss,      10,     20,   104},  // bank 0: activate 0, column 10
        {2048,   1,      Row::conflict,  32,     42,   126},  // row 1 after it: precharge 14, activate 22
        {64,     2,      Row::hit,       14,     24,   108},  // row 0 still open at 14: ahead of row 1
        {2112,   50,     Row::hit,       50,     60,   144},  // row 1 is the bank's last row again
    });
    DramBanks banks(c);
    for (auto [addr, at] : {std::pair<uint64_t, Cycle>{0, 0}, {2048, 1}, {64, 2}}) banks.access(addr, 64, at);
    const nlohmann::json j = banks.stats_json();
    EXPECT_EQ(j["row_hits_first"], 1);
    EXPECT_EQ(j["moved_back_cycles"], 4);
    EXPECT_EQ(j["scheduler"], "frfcfs");
    // First come, first served: request 3 waits behind the conflict and pays one of its own.
    run_table(small(), {
        {0,      0,      Row::miss,      10,     20,   104},
        {2048,   1,      Row::conflict,  32,     42,   126},
        {64,     2,      Row::conflict,  54,     64,   148},  // precharge 36, activate 44
        {2112,   50,     Row::conflict,  76,     86,   170},  // precharge 58, activate 66
    });
}

TEST(DramDetailed, ClosePageEveryAccessActivates) {
    run_table(small("close"), {
        {0,    0,   Row::miss, 10, 20, 104},  // bank 0 precharges after the burst: ready 10+4+8 = 22
        {64,   0,   Row::miss, 32, 42, 126},  // same row, but closed: activate at 22
        {2048, 100, Row::miss, 110, 120, 204},  // another row costs no precharge on the critical path
    });
}

TEST(DramDetailed, CountsRowOutcomesPerBank) {
    TestKernel kernel;
    Dram dram("dram", small());
    for (uint64_t addr : {0ull, 64ull, 2048ull, 1024ull, 2112ull}) dram.access({addr, 64, false, DataKind::node, 0});
    const nlohmann::json j = dram.stats_json(1000, 1.0);
    EXPECT_EQ(j["row_hits"], 2);
    EXPECT_EQ(j["row_misses"], 2);
    EXPECT_EQ(j["row_conflicts"], 1);
    EXPECT_DOUBLE_EQ(j["row_hit_rate"].get<double>(), 0.4);
    ASSERT_EQ(j["by_bank"].size(), 2u);
    EXPECT_EQ(j["by_bank"][0]["bank"], 0);
    EXPECT_EQ(j["by_bank"][0]["accesses"], 4);
    EXPECT_EQ(j["by_bank"][0]["row_conflicts"], 1);
    EXPECT_EQ(j["by_bank"][1]["row_misses"], 1);
    EXPECT_EQ(j["reads"], 5);
}

TEST(DramDetailed, UnloadedClosedBankMatchesBandwidthModelLatency) {
    // A closed-bank access costs exactly `latency + burst`, the bandwidth model's unloaded latency.
    TestKernel kernel;
    DramConfig c = small("close");  // every access finds its bank closed
    c.channels = 2;
    DramConfig calendars = c;
    calendars.model = DramModel::bandwidth;
    Dram bandwidth("bandwidth", calendars), banks("banks", c);
    for (Cycle t : {Cycle(0), Cycle(5000)}) {
        const uint64_t addr = 64 * 1024 * (t + 1);
        EXPECT_EQ(banks.access({addr, 64, false, DataKind::node, t}), bandwidth.access({addr, 64, false, DataKind::node, t}));
    }
}

TEST(DramDetailed, BusSaturatesAtChannelBandwidthOnRowHits) {
    // Streaming one open row: the data bus, not the banks, is the limit (16 B/cycle).
    TestKernel kernel;
    DramBanks banks(small());
    Cycle done = 0;
    for (uint64_t i = 0; i < 16; ++i) done = std::max(done, banks.access(i * 64, 64, 0).done);
    EXPECT_EQ(banks.row_hits(), 15u);
    EXPECT_EQ(done, 16u + 16 * 4);  // first data at tRCD + tCAS = 16, then 64 bus cycles
}

TEST(DramDetailed, RasDelaysAConflictsPrecharge) {
    DramConfig c = small();
    c.t_ras = 30;
    DramBanks banks(c);
    // Row 0 of bank 0 activated at 0 (column 10, burst to 14); row 1 of bank 0 at 14 must wait
    // for tRAS: precharge at 30, activate 38, column 48, data 54..57.
    EXPECT_EQ(banks.access(0, 64, 0).column, 10u);
    const DramBanks::Timing t = banks.access(2048, 64, 14);
    EXPECT_EQ(int(t.result), int(Row::conflict));
    EXPECT_EQ(t.column, 48u);
    EXPECT_EQ(t.done, 58u);
    EXPECT_EQ(t.ras_wait, 16u);
    EXPECT_EQ(banks.stats_json()["ras_wait_cycles"], 16);
}

TEST(DramDetailed, RrdAndFawSpaceActivatesOfAChannel) {
    DramConfig c = small();
    c.t_rrd = 6;
    DramBanks rrd(c);
    EXPECT_EQ(rrd.access(0, 64, 0).column, 10u);  // bank 0 activates at 0
    const DramBanks::Timing b = rrd.access(1024, 64, 0);  // bank 1: no sooner than 6
    EXPECT_EQ(b.column, 16u);
    EXPECT_EQ(b.activate_wait, 6u);
    // Four activates in one cycle fit a 40-cycle window; the fifth waits for the window to pass.
    c = small();
    c.banks = 8;
    c.t_faw = 40;
    DramBanks faw(c);
    for (uint64_t bank = 0; bank < 4; ++bank) EXPECT_EQ(faw.access(bank * 1024, 64, 0).column, 10u) << bank;
    const DramBanks::Timing fifth = faw.access(4 * 1024, 64, 0);
    EXPECT_EQ(fifth.column, 50u);
    EXPECT_EQ(fifth.activate_wait, 40u);
    // Back-filled before them, the window counts the later activates too.
    EXPECT_EQ(faw.access(5 * 1024, 64, 0).column, 50u + 0u);
}

DramConfig grouped() {
    // 4 banks in 2 groups: bank k (at k x 1024) in group k mod 2.
    DramConfig c = small();
    c.banks = 4;
    c.bank_groups = 2;
    return c;
}

TEST(DramDetailed, CcdLSpacesColumnsOfOneBankGroup) {
    DramConfig c = grouped();
    c.t_ccd_l = 12;
    DramBanks banks(c);
    EXPECT_EQ(banks.access(0, 64, 0).column, 10u);  // bank 0, group 0
    // Bank 2 is in group 0 too: its column no sooner than 10 + 12.
    const DramBanks::Timing same = banks.access(2 * 1024, 64, 0);
    EXPECT_EQ(same.column, 22u);
    EXPECT_EQ(same.column_wait, 12u);
    // Bank 1 is in group 1: only the data bus spaces it (data 20..23 after bank 0's 16..19).
    const DramBanks::Timing other = banks.access(1024, 64, 0);
    EXPECT_EQ(other.column, 10u);
    EXPECT_EQ(other.column_wait, 0u);
    EXPECT_EQ(other.done, 24u);
    EXPECT_EQ(banks.stats_json()["column_wait_cycles"], 12);
}

TEST(DramDetailed, GroupInterleavingAlternatesGroupsLineByLineAndKeepsTheMapABijection) {
    // 4 banks in 2 groups, 64-byte granules: line k of the channel in group k mod 2; within a
    // group the lines fill a 1 KiB row of its first bank, then its second bank's, then row 1.
    DramConfig c = grouped();
    c.group_interleave_bytes = 64;
    DramBanks banks(c);
    for (uint64_t line = 0; line < 8; ++line) EXPECT_EQ(banks.map(line * 64).group, line % 2) << line;
    const DramAddress a = banks.map(3 * 64 + 5);  // line 3: group 1, its line 1 in the group
    EXPECT_EQ(a.bank, 1u);
    EXPECT_EQ(a.column, 64u + 5u);
    EXPECT_EQ(a.row, 0u);
    const DramAddress b = banks.map(2 * 1024 + 64);  // line 33: group 1, its line 16: bank 3, column 0
    EXPECT_EQ(b.bank, 3u);
    EXPECT_EQ(b.column, 0u);
    EXPECT_EQ(b.row, 0u);
    std::map<std::tuple<uint32_t, uint64_t, uint32_t>, uint64_t> seen;  // every byte's own place
    for (uint64_t addr = 0; addr < 4 * 4 * 1024; addr += 16) {
        const DramAddress m = banks.map(addr);
        EXPECT_EQ(m.group, m.bank % 2);
        EXPECT_TRUE(seen.emplace(std::make_tuple(m.bank, m.row, m.column), addr).second) << addr;
    }
    // Streaming lines: with tCCD_L, lines in one group (no interleaving: a row's lines share a
    // bank) wait for it; alternating groups only for the bus.
    c.t_ccd_l = 12;
    DramConfig plain = c;
    plain.group_interleave_bytes = 0;
    DramBanks inter(c), flat(plain);
    Cycle end_inter = 0, end_flat = 0;
    for (uint64_t line = 0; line < 8; ++line) {
        end_inter = std::max(end_inter, inter.access(line * 64, 64, 0).done);
        end_flat = std::max(end_flat, flat.access(line * 64, 64, 0).done);
    }
    EXPECT_LT(end_inter, end_flat);
    EXPECT_GT(flat.stats_json()["column_wait_cycles"].get<uint64_t>(), inter.stats_json()["column_wait_cycles"].get<uint64_t>());
}

TEST(DramDetailed, RrdLSpacesActivatesOfOneBankGroup) {
    DramConfig c = grouped();
    c.t_rrd = 4;
    c.t_rrd_l = 9;
    DramBanks banks(c);
    EXPECT_EQ(banks.access(0, 64, 0).column, 10u);         // bank 0 activates at 0
    EXPECT_EQ(banks.access(1024, 64, 0).column, 14u);      // group 1: tRRD, activate at 4
    EXPECT_EQ(banks.access(2 * 1024, 64, 0).column, 19u);  // group 0: tRRD_L after 0, activate at 9
}

TEST(DramDetailed, TurnaroundsSpaceReadsAndWrites) {
    DramConfig c = grouped();
    c.t_wtr = 5;
    DramBanks wtr(c);
    // A write's data on the bus 16..19; a read's column no sooner than 20 + tWTR.
    EXPECT_EQ(wtr.access(0, 64, 0, true).column, 10u);
    const DramBanks::Timing read = wtr.access(1024, 64, 0);
    EXPECT_EQ(read.column, 25u);
    EXPECT_EQ(read.column_wait, 15u);
    // Reads after reads are not turned around.
    EXPECT_EQ(wtr.access(2 * 1024, 64, 0).column, 25u);
    // tWTR_L within the write's bank group, tWTR_S (t_wtr) across: bank 1 is in group 1, bank 2
    // in the write's group 0.
    c = grouped();
    c.t_wtr = 3;
    c.t_wtr_l = 9;
    DramBanks split(c);
    EXPECT_EQ(split.access(0, 64, 0, true).column, 10u);  // bank 0, group 0: data 16..19
    EXPECT_EQ(split.access(1024, 64, 0).column, 23u);     // group 1: 20 + 3
    EXPECT_EQ(split.access(2 * 1024, 64, 0).column, 29u); // group 0: 20 + 9
    c = grouped();
    c.t_rtw = 7;
    DramBanks rtw(c);
    EXPECT_EQ(rtw.access(0, 64, 0).column, 10u);
    EXPECT_EQ(rtw.access(1024, 64, 0, true).column, 17u);  // a write's column tRTW after the read's
    // A read stamped before a booked write, but too close to it, goes after the write's data.
    c = grouped();
    c.t_wtr = 5;
    c.t_rtw = 7;
    DramBanks both(c);
    EXPECT_EQ(both.access(0, 64, 20, true).column, 30u);  // write: column 30, data 36..39
    EXPECT_EQ(both.access(1024, 64, 17).column, 45u);     // read at 27 would precede it by 3 < 7: after 40 + 5
}

TEST(DramDetailed, AFullControllerQueueHoldsRequestsBack) {
    DramConfig c = grouped();
    c.queue_entries = 2;
    DramBanks banks(c);
    EXPECT_EQ(banks.access(0, 64, 0).done, 20u);     // data 16..19
    EXPECT_EQ(banks.access(1024, 64, 0).done, 24u);  // data 20..23
    // The third waits for the first to leave the queue (at 20): activate 20, column 30.
    const DramBanks::Timing third = banks.access(2 * 1024, 64, 0);
    EXPECT_EQ(third.start, 20u);
    EXPECT_EQ(third.queue_wait, 20u);
    EXPECT_EQ(third.column, 30u);
    const nlohmann::json j = banks.stats_json();
    EXPECT_EQ(j["queue_wait_cycles"], 20);
    EXPECT_EQ(j["queue_full_requests"], 1);
}

TEST(DramDetailed, RefreshBlocksTheChannelAndClosesRows) {
    DramConfig c = small();
    c.t_refi = 100;
    c.t_rfc = 20;
    DramBanks banks(c);
    // At 95 the access would run into the refresh at 100: it starts after it (120).
    const DramBanks::Timing a = banks.access(0, 64, 95);
    EXPECT_EQ(a.start, 120u);
    EXPECT_EQ(int(a.result), int(Row::miss));
    EXPECT_EQ(a.column, 130u);
    EXPECT_EQ(a.refresh_wait, 25u);
    EXPECT_EQ(int(banks.access(64, 64, 141).result), int(Row::hit));  // the row stayed open
    // At 205 the refresh at 200 is under way (to 220), and it closed the row.
    const DramBanks::Timing b = banks.access(128, 64, 205);
    EXPECT_EQ(b.start, 220u);
    EXPECT_EQ(int(b.result), int(Row::miss));
    EXPECT_EQ(b.column, 230u);
    // A gap between refreshes shorter than an access (outside any DDR part's timing) defers it
    // once, then lets it run past the next refresh: it ends.
    c.t_refi = 100;
    c.t_rfc = 90;
    DramBanks tight(c);
    const DramBanks::Timing d = tight.access(0, 64, 95);
    EXPECT_EQ(d.start, 190u);
    EXPECT_EQ(d.column, 200u);
}

/// The bank model as it was before its bookings became a ring: a std::map per bank, the same
/// rules (the reference the ring must reproduce access for access).
class MapBanks {
public:
    explicit MapBanks(const DramConfig& c) : m_c(c), m_map(c), m_banks(size_t(c.channels) * c.banks) {
        for (uint32_t i = 0; i < c.channels; ++i) m_buses.emplace_back(c.bytes_per_cycle, 1);
    }
    DramBanks::Timing access(uint64_t addr, uint32_t bytes, Cycle time) {
        const DramAddress a = m_map.map(addr);
        Bank& bank = m_banks[size_t(a.channel) * m_c.banks + a.bank];
        const bool close = m_c.page_policy == PagePolicy::close;
        const Cycle burst = (std::max<uint32_t>(bytes, 1) + m_c.bytes_per_cycle - 1) / m_c.bytes_per_cycle;
        const Cycle tail = burst + (close ? m_c.t_rp : 0);
        auto outcome = [&](uint64_t open) {
            if (open == a.row && !close) return Row::hit;
            return open == kClosed ? Row::miss : Row::conflict;
        };
        auto to_column = [&](Row r) {
            return r == Row::hit ? Cycle(0) : r == Row::miss ? Cycle(m_c.t_rcd) : Cycle(m_c.t_rp) + m_c.t_rcd;
        };
        auto next = bank.busy.upper_bound(time);
        uint64_t open = bank.base_row;
        Cycle s = time;
        if (next != bank.busy.begin()) {
            auto prev = std::prev(next);
            open = prev->second.second;
            s = std::max(s, prev->second.first);
        }
        Row result = outcome(open);
        while (next != bank.busy.end() && s + to_column(result) + tail > next->first) {
            s = std::max(s, next->second.first);
            open = next->second.second;
            result = outcome(open);
            ++next;
        }
        DramBanks::Timing t;
        t.start = s;
        t.result = result;
        t.column = s + to_column(result);
        bank.busy.emplace(s, std::make_pair(t.column + tail, close ? kClosed : a.row));
        while (bank.busy.size() > 64) {
            bank.base_row = bank.busy.begin()->second.second;
            bank.busy.erase(bank.busy.begin());
        }
        Cycle cycle = t.column + m_c.t_cas;
        uint32_t left = std::max<uint32_t>(bytes, 1);
        for (Cycle i = 0; i < burst; ++i) {
            const uint32_t chunk = std::min(left, m_c.bytes_per_cycle);
            cycle = m_buses[a.channel].reserve(cycle, chunk) + 1;
            left -= chunk;
        }
        t.done = cycle;
        return t;
    }

private:
    static constexpr uint64_t kClosed = ~0ull;
    struct Bank {
        std::map<Cycle, std::pair<Cycle, uint64_t>> busy;  ///< start -> (end, row after)
        uint64_t base_row = kClosed;
    };
    DramConfig m_c;
    DramBanks m_map;  ///< for its address map only
    std::vector<Bank> m_banks;
    std::vector<SlotCalendar> m_buses;
};

TEST(DramDetailed, RingBookingsMatchTheMapModelOnRandomOutOfOrderStreams) {
    // Random streams with arrivals up to far in the past (more than 64 bookings back) and in the
    // future, same-row runs and all outcomes, open and close page, one and two channels.
    for (const char* policy : {"open", "close"})
        for (uint32_t channels : {1u, 2u}) {
            DramConfig c = small(policy);
            c.channels = channels;
            DramBanks ring(c);
            MapBanks reference(c);
            std::mt19937_64 rng(channels * 7 + policy[0]);
            Cycle now = 0;
            uint64_t addr = 0;
            for (int i = 0; i < 20000; ++i) {
                now += rng() % 8;
                const int64_t skew = int64_t(rng() % 4000) - 3000;  // mostly earlier than now
                const Cycle t = skew < 0 && Cycle(-skew) > now ? 0 : Cycle(int64_t(now) + skew);
                addr = rng() % 4 ? addr + 64 : (rng() % 64) * 1024;  // runs in a row, then a jump
                const uint32_t bytes = rng() % 5 ? 64 : 20;
                const DramBanks::Timing a = ring.access(addr, bytes, t), b = reference.access(addr, bytes, t);
                ASSERT_EQ(a.start, b.start) << "access " << i;
                ASSERT_EQ(a.column, b.column) << "access " << i;
                ASSERT_EQ(a.done, b.done) << "access " << i;
                ASSERT_EQ(a.result, b.result) << "access " << i;
            }
        }
}

}  // namespace
}  // namespace rtsim
