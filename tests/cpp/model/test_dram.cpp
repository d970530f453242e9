// DRAM: unloaded latency, saturation at channels x bytes_per_cycle, channel interleaving.
#include <gtest/gtest.h>

#include <algorithm>

#include "rtl_model/mem/dram.h"
#include "model_test_util.h"

namespace rtsim {
namespace {

using test::TestKernel;

constexpr Cycle kLatency = 100;

DramConfig two_channels() {
    DramConfig c;
    c.channels = 2;
    c.bytes_per_cycle = 16;  // peak 32 B/cycle over both channels
    c.latency = uint32_t(kLatency);
    c.interleave_bytes = 256;
    c.model = DramModel::bandwidth;  // these tests check the bandwidth calendars
    return c;
}

/// Bytes per cycle delivered by `n` reads of 64 B (read i at cycle i * gap, address i * stride):
/// all bytes over the cycles until the last byte is transferred.
double delivered_rate(Dram& dram, uint64_t n, double gap, uint64_t stride) {
    Cycle end = 0;
    for (uint64_t i = 0; i < n; ++i)
        end = std::max(end, dram.access({i * stride, 64, false, DataKind::node, Cycle(double(i) * gap)}) - kLatency);
    return double(n * 64) / double(end);
}

TEST(Dram, UnloadedLatencyIsLatencyPlusTransfer) {
    TestKernel kernel;
    Dram dram("dram", two_channels());
    EXPECT_EQ(dram.access({0, 64, false, DataKind::node, 1000}), 1000 + kLatency + 64 / 16);
    EXPECT_EQ(dram.access({4096, 20, true, DataKind::hit, 5003}), 5003 + kLatency + 2);  // 20 B: 2 cycles
    EXPECT_EQ(dram.queue_cycles(), 0u);
    EXPECT_EQ(dram.stats()[DataKind::node].read_bytes, 64u);
    EXPECT_EQ(dram.stats()[DataKind::hit].write_bytes, 20u);
}

TEST(Dram, SaturatesAtConfiguredBandwidthWhenAllRequestsArriveAtOnce) {
    TestKernel kernel;
    Dram dram("dram", two_channels());
    const uint64_t n = 20000;
    EXPECT_NEAR(delivered_rate(dram, n, 0.0, 64), 32.0, 32.0 * 0.03);
    // No 1024-cycle bucket ever moves more than the peak.
    uint64_t total = 0;
    for (uint64_t bytes : dram.bytes_over_time()) {
        EXPECT_LE(bytes, 32u * Dram::bucket_cycles());
        total += bytes;
    }
    EXPECT_EQ(total, n * 64);
    // Bandwidth stats: at 1 GHz 32 B/cycle is 32 GB/s.
    const nlohmann::json j = dram.stats_json(Cycle(n * 64 / 32), 1.0);
    EXPECT_DOUBLE_EQ(j["peak_bandwidth_gbps"].get<double>(), 32.0);
    EXPECT_NEAR(j["bandwidth_utilization"].get<double>(), 1.0, 1e-9);
    EXPECT_GT(j["avg_queue_cycles"].get<double>(), 1000.0);
}

TEST(Dram, BandwidthOverTimeNeverExceedsThePeakWhenTransfersStraddleBuckets) {
    TestKernel kernel;
    DramConfig c = two_channels();
    c.channels = 1;  // 16 B/cycle; 48-byte transfers take 3 cycles, and 1024 is no multiple of 3
    Dram dram("dram", c);
    for (uint64_t i = 0; i < 3000; ++i) dram.access({i * 64, 48, false, DataKind::node, 0});
    uint64_t total = 0;
    const auto& buckets = dram.bytes_over_time();
    for (size_t b = 0; b < buckets.size(); ++b) {
        EXPECT_LE(buckets[b], 16u * Dram::bucket_cycles()) << "bucket " << b;
        total += buckets[b];
    }
    EXPECT_EQ(total, 3000u * 48);
    EXPECT_GE(buckets[1], 15u * Dram::bucket_cycles());  // saturated: close to the peak
}

TEST(Dram, SaturatesAtConfiguredBandwidthUnderOverload) {
    TestKernel kernel;
    Dram dram("dram", two_channels());
    // Offered: 64 B per cycle, twice the peak.
    EXPECT_NEAR(delivered_rate(dram, 20000, 1.0, 64), 32.0, 32.0 * 0.03);
}

TEST(Dram, BelowPeakNothingQueues) {
    TestKernel kernel;
    Dram dram("dram", two_channels());
    // Offered: 64 B every 4 cycles (16 B/cycle, half the peak), spread over both channels.
    for (uint64_t i = 0; i < 5000; ++i) {
        Cycle t = i * 4;
        EXPECT_EQ(dram.access({i * 64, 64, false, DataKind::node, t}), t + kLatency + 4) << "read " << i;
    }
    EXPECT_EQ(dram.queue_cycles(), 0u);
}

TEST(Dram, ChannelInterleavingSpreadsAddresses) {
    // Addresses 512 B apart with 2 channels interleaved every 256 B all land on channel 0: half
    // the bandwidth. Consecutive lines alternate channels every 256 B: full bandwidth.
    TestKernel kernel;
    Dram one("one_channel", two_channels());
    EXPECT_NEAR(delivered_rate(one, 10000, 0.0, 512), 16.0, 16.0 * 0.03);
    Dram both("both_channels", two_channels());
    EXPECT_NEAR(delivered_rate(both, 10000, 0.0, 256), 32.0, 32.0 * 0.03);
    // More channels, more bandwidth.
    DramConfig four = two_channels();
    four.channels = 4;
    Dram wide("four_channels", four);
    EXPECT_NEAR(delivered_rate(wide, 20000, 0.0, 64), 64.0, 64.0 * 0.03);
}

}  // namespace
}  // namespace rtsim
