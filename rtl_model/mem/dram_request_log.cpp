#include "rtl_model/mem/dram_request_log.h"

#include <algorithm>
#include <cstdio>
#include <fstream>

#include "traces/common/error.h"

namespace rtsim {

void DramRequestLog::add(const DramRequestRecord& r) {
    if (m_records.size() < kMaxRecords) m_records.push_back(r);
    else ++m_dropped;
}

std::vector<DramRequestRecord> DramRequestLog::in_issue_order() const {
    // Units run up to a quantum apart at approx, so requests reach DRAM out of order; a stable
    // sort keeps the arrival order of requests stamped with the same cycle.
    std::vector<DramRequestRecord> sorted = m_records;
    std::stable_sort(sorted.begin(), sorted.end(),
                     [](const DramRequestRecord& a, const DramRequestRecord& b) { return a.issue < b.issue; });
    return sorted;
}

namespace {

std::ofstream open_for_writing(const std::string& path) {
    std::ofstream out(path);
    require(bool(out), path + ": cannot write the DRAM trace");
    return out;
}

}  // namespace

void DramRequestLog::write_dramsim3(const std::string& path) const {
    std::ofstream out = open_for_writing(path);
    char line[64];
    for (const DramRequestRecord& r : in_issue_order()) {
        const uint32_t bursts = std::max<uint32_t>(1, (r.bytes + kDramsim3Bytes - 1) / kDramsim3Bytes);
        for (uint32_t b = 0; b < bursts; ++b) {
            std::snprintf(line, sizeof line, "0x%llX %s %llu\n",
                          static_cast<unsigned long long>(r.addr + uint64_t(b) * kDramsim3Bytes),
                          r.write ? "WRITE" : "READ", static_cast<unsigned long long>(r.issue));
            out << line;
        }
    }
}

void DramRequestLog::write_csv(const std::string& path) const {
    std::ofstream out = open_for_writing(path);
    out << "addr,write,bytes,issue,ready\n";
    for (const DramRequestRecord& r : in_issue_order())
        out << r.addr << ',' << int(r.write) << ',' << r.bytes << ',' << r.issue << ',' << r.ready << '\n';
}

nlohmann::json DramRequestLog::summary() const {
    uint64_t reads = 0, writes = 0, bytes = 0;
    double read_latency = 0;
    Cycle first = ~Cycle(0), last = 0;
    for (const DramRequestRecord& r : m_records) {
        (r.write ? writes : reads) += 1;
        bytes += r.bytes;
        if (!r.write) read_latency += double(r.ready - r.issue);
        first = std::min(first, r.issue);
        last = std::max(last, r.ready);
    }
    const bool any = !m_records.empty();
    const double span = any && last > first ? double(last - first) : 0.0;
    return {{"requests", m_records.size()},
            {"reads", reads},
            {"writes", writes},
            {"bytes", bytes},
            {"dropped", m_dropped},
            {"first_issue_cycle", any ? first : 0},
            {"last_ready_cycle", last},
            {"mean_read_latency_cycles", reads ? read_latency / double(reads) : 0.0},
            {"bandwidth_bytes_per_cycle", span > 0 ? double(bytes) / span : 0.0}};
}

}  // namespace rtsim
