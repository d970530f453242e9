#include "sim/harness/latency_histogram.h"

namespace rtsim {

namespace {
constexpr int kSub = 3;  // 2^3 = 8 sub-buckets per octave
}

size_t LatencyHistogram::bucket(uint64_t v) {
    if (v < (1u << kSub)) return size_t(v);
    int msb = 63 - __builtin_clzll(v);
    uint64_t sub = (v >> (msb - kSub)) & ((1u << kSub) - 1);
    return size_t((msb - kSub + 1) << kSub) + size_t(sub);
}

uint64_t LatencyHistogram::upper(size_t b) {
    if (b < (1u << kSub)) return b;
    int octave = int(b >> kSub) + kSub - 1;
    uint64_t sub = b & ((1u << kSub) - 1);
    // Inclusive: the last value of the bucket (buckets below 8 hold one value each).
    return (((uint64_t(1) << kSub | sub) + 1) << (octave - kSub)) - 1;
}

void LatencyHistogram::add(uint64_t cycles) {
    size_t b = bucket(cycles);
    if (b >= m_buckets.size()) m_buckets.resize(b + 1, 0);
    ++m_buckets[b];
    ++m_count;
    m_sum += cycles;
    if (cycles > m_max) m_max = cycles;
}

uint64_t LatencyHistogram::quantile(double q) const {
    uint64_t target = uint64_t(q * double(m_count)), seen = 0;
    for (size_t b = 0; b < m_buckets.size(); ++b) {
        seen += m_buckets[b];
        if (seen > target) return upper(b) < m_max ? upper(b) : m_max;
    }
    return m_max;
}

nlohmann::json LatencyHistogram::to_json() const {
    nlohmann::json upper_bounds = nlohmann::json::array(), counts = nlohmann::json::array();
    for (size_t b = 0; b < m_buckets.size(); ++b) {
        if (!m_buckets[b]) continue;
        upper_bounds.push_back(upper(b));
        counts.push_back(m_buckets[b]);
    }
    return {{"rays", m_count},
            {"mean_cycles", mean()},
            {"p50_cycles", quantile(0.5)},
            {"p95_cycles", quantile(0.95)},
            {"p99_cycles", quantile(0.99)},
            {"max_cycles", m_max},
            {"histogram", {{"bucket_upper_cycles", upper_bounds}, {"rays", counts}}}};
}

const StatBlock& latency_stats() {
    static const StatBlock block{
        "latency",
        {
            {"rays", "rays", "rays recorded (= `summary.rays`)"},
            {"mean_cycles", "cycles", "exact mean (the analytic level: the mean unloaded latency)"},
            {"p50_cycles", "cycles", "inclusive upper bound of the bucket holding the median (at most `max_cycles`); not at the statistical analytic level", false, true},
            {"p95_cycles", "cycles", "the same for the 95th percentile", false, true},
            {"p99_cycles", "cycles", "the same for the 99th percentile", false, true},
            {"max_cycles", "cycles", "exact maximum", false, true},
            {"histogram", "", "`bucket_upper_cycles`: inclusive upper bound of each non-empty bucket, ascending; `rays`: rays in each", false, true},
            {"estimated", "", "the statistical analytic level only: what `mean_cycles` estimates", false, true},
        }};
    return block;
}

RTSIM_REGISTER_STAT_BLOCK(latency_stats)

}  // namespace rtsim
