#pragma once
// Usage of a resource over time: an amount (bytes, issues, accesses, busy cycles) summed per
// bucket of kBucketCycles cycles from cycle 0, for utilisation-over-time stats and the timeline.
// Adding is O(1) amortised; the JSON form is resampled to at most kPoints points.
#include <algorithm>
#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "rtl_model/common/interfaces.h"

namespace rtsim {

class UsageSeries {
public:
    static constexpr Cycle kBucketCycles = 1024;
    static constexpr size_t kPoints = 256;

    void add(Cycle time, uint64_t amount) {
        const size_t b = size_t(time / kBucketCycles);
        if (b >= m_buckets.size()) m_buckets.resize(b + 1, 0);
        m_buckets[b] += amount;
    }
    /// Spreads `amount` per cycle over [start, end) (e.g. an MSHR held for a miss).
    void add_interval(Cycle start, Cycle end) {
        for (Cycle t = start; t < end;) {
            const Cycle bucket_end = (t / kBucketCycles + 1) * kBucketCycles, stop = std::min(end, bucket_end);
            add(t, stop - t);
            t = stop;
        }
    }
    /// Spreads `amount` over the cycles from `start` at `per_cycle` a cycle (a transfer of
    /// `amount` bytes over a bus of `per_cycle` bytes a cycle), so a transfer straddling a
    /// bucket's end is split between the buckets and no bucket holds more than its cycles allow.
    void add_spread(Cycle start, uint64_t amount, uint64_t per_cycle) {
        per_cycle = per_cycle ? per_cycle : amount;
        for (Cycle t = start; amount > 0;) {
            const Cycle bucket_end = (t / kBucketCycles + 1) * kBucketCycles;
            const uint64_t part = std::min<uint64_t>(amount, (bucket_end - t) * per_cycle);
            add(t, part);
            amount -= part;
            t = bucket_end;
        }
    }
    const std::vector<uint64_t>& buckets() const { return m_buckets; }
    uint64_t total() const {
        uint64_t sum = 0;
        for (uint64_t b : m_buckets) sum += b;
        return sum;
    }
    /// Adds another series bucket by bucket (e.g. the same resource of every unit).
    UsageSeries& operator+=(const UsageSeries& o) {
        if (o.m_buckets.size() > m_buckets.size()) m_buckets.resize(o.m_buckets.size(), 0);
        for (size_t i = 0; i < o.m_buckets.size(); ++i) m_buckets[i] += o.m_buckets[i];
        return *this;
    }

    /// [{cycle, value}]: value = amount per cycle / capacity per cycle over each point's cycles
    /// (a utilisation in [0, 1] when capacity is the resource's peak per cycle).
    nlohmann::json to_json(double capacity_per_cycle) const {
        nlohmann::json out = nlohmann::json::array();
        const size_t n = m_buckets.size(), group = std::max<size_t>(1, (n + kPoints - 1) / kPoints);
        for (size_t i = 0; i < n; i += group) {
            uint64_t sum = 0;
            const size_t end = std::min(n, i + group);
            for (size_t k = i; k < end; ++k) sum += m_buckets[k];
            const double cycles = double((end - i) * kBucketCycles);
            out.push_back({{"cycle", i * kBucketCycles},
                           {"value", capacity_per_cycle > 0 ? double(sum) / cycles / capacity_per_cycle : 0.0}});
        }
        return out;
    }

private:
    std::vector<uint64_t> m_buckets;
};

}  // namespace rtsim
