// The DRAM latency the verdict's estimates charge: the judged run's row outcomes (its bank wait
// is reported, not charged).
#include <gtest/gtest.h>

#include "sim/report/dram_latency_calibration.h"

namespace rtsim {
namespace {

TEST(DramLatencyCalibration, AddsTheRowOutcomeTheRunMeasured) {
    SimConfig c;  // bank model, t_rp = t_rcd = 14
    const nlohmann::json dram = {
        {"row_hits", 150}, {"row_misses", 50}, {"row_conflicts", 800}, {"avg_queue_cycles", 13.3}};
    const DramLatencyCalibration k = calibrate_dram_latency(c, dram);
    ASSERT_TRUE(k.measured);
    EXPECT_DOUBLE_EQ(k.row_cycles, (800.0 * 14 - 150.0 * 14) / 1000.0);  // 9.1
    EXPECT_DOUBLE_EQ(k.bank_wait, 13.3);
    EXPECT_EQ(k.added_cycles(), 9u);  // the bank wait is queueing: reported, not charged
    EXPECT_EQ(k.apply(c).dram.latency, c.dram.latency + 9);
    EXPECT_EQ(k.to_json()["added_cycles"], 9);
    EXPECT_DOUBLE_EQ(k.to_json()["bank_wait_cycles"].get<double>(), 13.3);
}

TEST(DramLatencyCalibration, RowHitsCanOnlyShortenItToTheClosedBankLatency) {
    SimConfig c;
    const nlohmann::json dram = {{"row_hits", 1000}, {"row_misses", 0}, {"row_conflicts", 0}, {"avg_queue_cycles", 2.0}};
    EXPECT_EQ(calibrate_dram_latency(c, dram).added_cycles(), 0u);  // -14: never below dram.latency
}

TEST(DramLatencyCalibration, NothingWithoutTheBankModelsCounts) {
    SimConfig c;
    EXPECT_FALSE(calibrate_dram_latency(c, nlohmann::json::object()).measured);
    EXPECT_FALSE(calibrate_dram_latency(c, nullptr).measured);
    c.dram.model = DramModel::bandwidth;  // its queue wait is bus time, which the closed form has
    const nlohmann::json dram = {{"row_hits", 1}, {"row_misses", 1}, {"row_conflicts", 1}, {"avg_queue_cycles", 9.0}};
    const DramLatencyCalibration k = calibrate_dram_latency(c, dram);
    EXPECT_FALSE(k.measured);
    EXPECT_EQ(k.apply(c).dram.latency, c.dram.latency);
    EXPECT_TRUE(k.to_json().is_null());
}

}  // namespace
}  // namespace rtsim
