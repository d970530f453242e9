// The DRAM request log behind --dram-trace: what it keeps, and the DRAMsim3 trace it writes.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "rtl_model/mem/dram.h"
#include "rtl_model/mem/dram_request_log.h"
#include "model_test_util.h"
#include "../process_temp_dir.h"

namespace rtsim {
namespace {

using test::TestKernel;

DramConfig bandwidth_dram() {
    DramConfig c;
    c.channels = 1;
    c.bytes_per_cycle = 16;
    c.latency = 100;
    c.model = DramModel::bandwidth;  // exact latencies: latency + transfer when unloaded
    return c;
}

std::string read_text(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

TEST(DramRequestLog, KeepsEveryRequestWithTheCycleTheModelServedIt) {
    TestKernel kernel;
    Dram dram("dram", bandwidth_dram());
    DramRequestLog log;
    dram.record_requests(&log);
    const Cycle r0 = dram.access({0x1000, 128, false, DataKind::node, 50});
    const Cycle r1 = dram.access({0x2000, 64, true, DataKind::hit, 10});
    ASSERT_EQ(log.records().size(), 2u);
    EXPECT_EQ(log.records()[0].ready, r0);
    EXPECT_EQ(log.records()[0].ready, 50u + 100 + 8);  // unloaded: latency + 128 B / 16 B per cycle
    EXPECT_EQ(log.records()[1].issue, 10u);
    EXPECT_EQ(log.records()[1].ready, r1);
    EXPECT_TRUE(log.records()[1].write);
    const nlohmann::json s = log.summary();
    EXPECT_EQ(s["reads"], 1);
    EXPECT_EQ(s["writes"], 1);
    EXPECT_EQ(s["bytes"], 192);
    EXPECT_DOUBLE_EQ(s["mean_read_latency_cycles"].get<double>(), 108.0);
    dram.record_requests(nullptr);
    dram.access({0x3000, 64, false, DataKind::node, 60});
    EXPECT_EQ(log.records().size(), 2u);  // stopped
}

TEST(DramRequestLog, WritesDramsim3LinesInIssueOrderOneBurstEach) {
    DramRequestLog log;
    log.add({0x1000, 30, 150, 128, false});  // two 64-byte bursts
    log.add({0x2A40, 20, 130, 64, true});    // issued earlier, logged later (approx's quantum)
    const auto dir = test::process_temp_dir("dram_request_log");
    log.write_dramsim3((dir / "t.txt").string());
    EXPECT_EQ(read_text(dir / "t.txt"), "0x2A40 WRITE 20\n0x1000 READ 30\n0x1040 READ 30\n");
    log.write_csv((dir / "t.csv").string());
    EXPECT_EQ(read_text(dir / "t.csv"), "addr,write,bytes,issue,ready\n10816,1,64,20,130\n4096,0,128,30,150\n");
}

}  // namespace
}  // namespace rtsim
