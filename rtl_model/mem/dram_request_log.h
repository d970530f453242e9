#pragma once
// The requests that reached DRAM, kept when a run asks for them (rtsim-sim --dram-trace), so
// another DRAM simulator can replay the same stream (docs/model.md, "Against DRAMsim3"). Written
// in DRAMsim3's text trace (Li et al., "DRAMsim3: a cycle-accurate, thermal-capable DRAM
// simulator", IEEE CAL 2020): `0xADDR READ|WRITE CYCLE`, one transaction a line, in issue order;
// and as rtsim's own record (CSV: address, write, bytes, issue and ready cycle), which carries
// the latency rtsim gave each request for the comparison. Cycles are rtsim's core cycles: the
// replaying script converts them to the other simulator's memory clock.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rtl_model/common/interfaces.h"

namespace rtsim {

struct DramRequestRecord {
    uint64_t addr = 0;
    Cycle issue = 0;  ///< cycle the request reached DRAM
    Cycle ready = 0;  ///< cycle rtsim's DRAM model returned its data (reads) or accepted it (writes)
    uint32_t bytes = 0;
    bool write = false;
};

class DramRequestLog {
public:
    /// Requests kept at most (24 bytes each: 16 M is 400 MB); later ones are counted, not kept.
    static constexpr size_t kMaxRecords = size_t(1) << 24;
    /// DRAMsim3's transaction: one 64-byte burst (a x64 channel's BL8); a longer request is
    /// written as consecutive bursts issued in the same cycle.
    static constexpr uint32_t kDramsim3Bytes = 64;

    void add(const DramRequestRecord& r);
    const std::vector<DramRequestRecord>& records() const { return m_records; }
    uint64_t dropped() const { return m_dropped; }
    /// The records in issue order (the order DRAMsim3 reads them).
    std::vector<DramRequestRecord> in_issue_order() const;
    /// Writes the DRAMsim3 trace (core cycles) to `path`.
    void write_dramsim3(const std::string& path) const;
    /// Writes rtsim's record (`addr,write,bytes,issue,ready`, a header line first) to `path`.
    void write_csv(const std::string& path) const;
    /// {requests, reads, writes, bytes, dropped, first_issue_cycle, last_ready_cycle,
    ///  mean_read_latency_cycles, bandwidth_bytes_per_cycle (bytes over first issue to last ready)}
    nlohmann::json summary() const;

private:
    std::vector<DramRequestRecord> m_records;
    uint64_t m_dropped = 0;
};

}  // namespace rtsim
