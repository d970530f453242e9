#include "rtl_model/mem/dram.h"

#include <algorithm>

namespace rtsim {

namespace {
constexpr uint32_t kWindowCycles = 32;  // calendar granularity; bandwidth is exact per window
constexpr size_t kTimelinePoints = 256;
}  // namespace

Dram::Dram(sc_core::sc_module_name name, const DramConfig& config)
    : sc_core::sc_module(name),
      m_config(config),
      m_interleave(config.interleave_bytes),
      m_channel_of(config.channels),
      m_transfer(config.bytes_per_cycle) {
    if (config.model == DramModel::banks) {
        m_banks = std::make_unique<DramBanks>(config);
        return;
    }
    for (uint32_t c = 0; c < config.channels; ++c)
        m_channels.emplace_back(uint64_t(config.bytes_per_cycle) * kWindowCycles, kWindowCycles);
}

Cycle Dram::access(const MemRequest& req) {
    MemCounters& c = m_stats[req.kind];
    if (req.write) {
        ++c.writes;
        c.write_bytes += req.bytes;
    } else {
        ++c.reads;
        ++c.read_hits;  // DRAM serves every read
        c.read_bytes += req.bytes;
    }
    Cycle start, ready, data;  // data: the first cycle the bytes are on the bus
    if (m_banks) {
        // Bank, row buffer and data bus timing; the rest of `latency` is a fixed front end.
        const DramBanks::Timing t = m_banks->access(req.addr, req.bytes, req.time, req.write);
        start = t.start;
        data = t.done - std::min<Cycle>(t.done, (req.bytes + m_config.bytes_per_cycle - 1) / m_config.bytes_per_cycle);
        const Cycle bank_part = Cycle(m_config.t_rcd) + m_config.t_cas;
        ready = t.done + (m_config.latency > bank_part ? m_config.latency - bank_part : 0);
    } else {
        BandwidthCalendar& channel = m_channels[m_channel_of.mod(m_interleave.div(req.addr))];
        start = channel.reserve(req.time, req.bytes);
        Cycle transfer = m_transfer.div(req.bytes + m_config.bytes_per_cycle - 1);
        ready = start + m_config.latency + transfer;
        data = start;
    }
    m_queue_cycles += start - req.time;
    if (m_log) m_log->add({req.addr, req.time, ready, req.bytes, req.write});
    if (req.info) req.info->level = ServedBy::dram;
    // Bytes are counted when they move on the channel, at its rate (with the bank model, on the
    // data bus after the column command, not when the bank started): a transfer straddling a
    // bucket's end is split, so bandwidth over time does not show a bucket above the peak.
    m_bytes_use.add_spread(data, req.bytes, m_config.bytes_per_cycle);
    return ready;
}

nlohmann::json Dram::stats_json(Cycle total_cycles, double clock_ghz) const {
    nlohmann::json j;
    StatsWriter w(dram_stats(), j);
    w.merge(dram_counters_json(m_stats));
    MemCounters t = m_stats.total();
    dram_bandwidth_stats(w, m_config, double(t.read_bytes + t.write_bytes), double(total_cycles), clock_ghz);
    w.set("avg_queue_cycles", (t.reads + t.writes) ? double(m_queue_cycles) / double(t.reads + t.writes) : 0.0);
    // Bandwidth over time, resampled to at most kTimelinePoints points.
    const std::vector<uint64_t>& buckets = m_bytes_use.buckets();
    size_t n = buckets.size(), group = std::max<size_t>(1, (n + kTimelinePoints - 1) / kTimelinePoints);
    nlohmann::json series = nlohmann::json::array();
    for (size_t i = 0; i < n; i += group) {
        uint64_t bytes = 0;
        size_t end = std::min(n, i + group);
        for (size_t k = i; k < end; ++k) bytes += buckets[k];
        double cycles = double((end - i) * bucket_cycles());
        series.push_back({{"cycle", i * bucket_cycles()}, {"gbps", double(bytes) / cycles * clock_ghz}});
    }
    w.set("bandwidth_over_time", series);
    if (m_banks) w.merge(m_banks->stats_json());
    w.done();
    return j;
}

}  // namespace rtsim
