#pragma once
// DRAM: channels interleaved by address. With model "banks" (the default) timing comes from
// DramBanks (banks, row buffers, activate/precharge, exact per-cycle data bus): `latency` is the
// unloaded latency of an access to a closed bank, split into tRCD + tCAS at the bank and a fixed
// front end of latency - tRCD - tCAS. With model "bandwidth" each channel is a bandwidth calendar
// of bytes per cycle plus a fixed latency: requests beyond a channel's bandwidth queue (start
// later), so delivered bandwidth saturates at channels x bytes_per_cycle (tested).
#include <cstdint>
#include <memory>
#include <vector>

#include <systemc>

#include "rtl_model/common/calendar.h"
#include "rtl_model/common/usage_series.h"
#include "rtl_model/mem/dram_banks.h"
#include "rtl_model/mem/mem_stats.h"
#include "rtl_model/mem/dram_config.h"
#include "rtl_model/mem/dram_request_log.h"

namespace rtsim {

class Dram : public sc_core::sc_module, public MemIf {
public:
    Dram(sc_core::sc_module_name name, const DramConfig& config);

    Cycle access(const MemRequest& req) final;

    const MemStats& stats() const { return m_stats; }
    /// Bytes moved per bucket of `bucket_cycles()` cycles, from cycle 0.
    const std::vector<uint64_t>& bytes_over_time() const { return m_bytes_use.buckets(); }
    const UsageSeries& bytes_use() const { return m_bytes_use; }
    static constexpr Cycle bucket_cycles() { return UsageSeries::kBucketCycles; }
    /// Peak bytes per cycle over all channels.
    double peak_bytes_per_cycle() const { return double(m_config.bytes_per_cycle) * m_config.channels; }
    uint64_t queue_cycles() const { return m_queue_cycles; }
    nlohmann::json stats_json(Cycle total_cycles, double clock_ghz) const;
    /// The bank model (model "banks"), else null.
    const DramBanks* banks() const { return m_banks.get(); }
    /// Keeps every request from now on in `log` (null: stop); the log outlives the run.
    void record_requests(DramRequestLog* log) { m_log = log; }

private:
    DramConfig m_config;
    std::vector<BandwidthCalendar> m_channels;
    Divider m_interleave, m_channel_of, m_transfer;  ///< addr -> block -> channel; bytes -> cycles
    std::unique_ptr<DramBanks> m_banks;
    MemStats m_stats;
    UsageSeries m_bytes_use;  ///< bytes moved over time
    uint64_t m_queue_cycles = 0;
    DramRequestLog* m_log = nullptr;  ///< the requests kept for another simulator (--dram-trace)
};

}  // namespace rtsim
