// Detailed DRAM (fidelity = detailed): banks, row buffers, activate/precharge/column timing and
// the data bus, against hand-worked sequences (docs/model.md, "Detailed DRAM").
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace rtsim
