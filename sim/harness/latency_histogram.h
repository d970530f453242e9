#pragma once
// Per-ray latency histogram: 8 buckets per power of two (12.5% resolution), exact mean and max.
#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "rtl_model/common/stats.h"

namespace rtsim {

class LatencyHistogram {
public:
    void add(uint64_t cycles);
    uint64_t count() const { return m_count; }
    double mean() const { return m_count ? double(m_sum) / double(m_count) : 0.0; }
    uint64_t max() const { return m_max; }
    /// Upper bound (inclusive, at most max()) of the bucket holding quantile q (0..1).
    uint64_t quantile(double q) const;
    nlohmann::json to_json() const;

private:
    static size_t bucket(uint64_t v);
    static uint64_t upper(size_t b);
    std::vector<uint64_t> m_buckets;
    uint64_t m_count = 0, m_sum = 0, m_max = 0;
};

/// stats.json "latency", declared once.
const StatBlock& latency_stats();

}  // namespace rtsim
