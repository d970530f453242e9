#pragma once
// Reuse distances and what they say about LRU caches of every size: the statistical cache model
// of the analytic level (docs/fidelity.md, "The analytic level").
//
// StatStack (Eklov & Hagersten, ISPASS 2010): the reuse distance of an access is the number of
// accesses since the previous access to the same line in the same stream. Under stationarity,
// the expected LRU stack distance (distinct other lines in between) of a reuse spanning D
// accesses is  SD(D) = sum_{m=1}^{D-1} P(RD > m),  where P(RD > m) is the survival function of
// the reuse distances themselves. One histogram of reuse distances therefore predicts the miss
// ratio of a fully associative LRU cache of any size: an access misses when SD(D) >= lines.
//
// Set associativity: the lines in between fall into the access's set at random (1 / sets each),
// so an access with stack distance s hits a W-way set-associative LRU cache with probability
// P(Binomial(s, 1 / sets) < W) (Smith 1978, "A comparative study of set associative memory
// mapping algorithms"; Hill & Smith 1989).
//
// Censoring: reuse distances are sampled in clusters of rays (sample.h); an access with
// no earlier access to its line in the cluster has a distance known only to exceed its position
// in the cluster. The survival function is the Kaplan-Meier (1958) estimate over observed and
// censored distances; a censored access hits with the conditional probability given that bound.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <vector>

#include "sim/analytic/probe_table.h"
#include "traces/common/huge_pages.h"

namespace rtsim {

/// Log-spaced bins of distances >= 1: kSubBins per octave; bin 0 holds distance 1.
struct DistanceBins {
    static constexpr int kSubBins = 4;
    static constexpr int kBins = 40 * kSubBins;  ///< up to 2^40
    static int bin(uint64_t d);
    static double low(int b);   ///< smallest distance in bin b (real-valued edge)
    static double high(int b);  ///< edge to the next bin
};

/// Survival function of reuse distances (Kaplan-Meier over observed and censored ones) and the
/// StatStack stack distance it implies.
class ReuseCurve {
public:
    /// `events[b]`: reuses observed in bin b; `censored[b]`: accesses whose distance exceeds bin
    /// b's low edge with no reuse seen in the window.
    ReuseCurve(const std::vector<double>& events, const std::vector<double>& censored);
    /// P(RD > d), log-linear between bin edges.
    double survival(double d) const;
    /// Expected stack distance of a reuse spanning d accesses: sum_{m=1}^{d-1} P(RD > m).
    double stack_distance(double d) const;
    /// Smallest reuse distance whose stack distance reaches `lines` (infinity if none does).
    double distance_for(double lines) const;

private:
    std::vector<double> m_surv;  ///< survival at each bin's high edge
    std::vector<double> m_sd;    ///< stack distance at each bin's high edge
};

/// Probability that an access with (expected) stack distance `sd` hits a LRU cache of `lines`
/// lines and `ways` ways (sets = lines / ways), random set mapping.
double lru_hit_probability(double sd, double lines, uint32_t ways);

/// Miss probability of an access in bin b of a stream whose curve is `curve`, for a cache of
/// `lines` x `ways`, averaged over the bin (log-uniform within it). Censored: the distance is
/// only known to exceed the bin's low edge; `censored_is_cold` when the window started at the
/// beginning of the trace (nothing before it: a censored access is a compulsory miss).
double bin_miss_probability(const ReuseCurve& curve, int b, bool censored, double lines, uint32_t ways,
                            bool censored_is_cold = false);

/// The last access position of each line (a key), cleared per cluster; the analysis's hot loop
/// does one exchange per access and stream. The table grows to tens of MB on a large scene and is
/// probed at random, so it lies on huge pages (no TLB miss per probe).
class LastUse {
public:
    explicit LastUse(size_t capacity_pow2 = 1u << 16) : m_table(capacity_pow2) {}
    /// Returns the previous value for `key` (or ~0 when absent) and stores `value`.
    uint64_t exchange(uint64_t key, uint64_t value) {
        bool found;
        uint64_t& slot = m_table.find_or_add(key, found);
        const uint64_t old = found ? slot : ~0ull;
        slot = value;
        return old;
    }
    /// The slot of `key` (added, `found` false, when absent): read it and store later, while no
    /// other key is added.
    uint64_t& slot(uint64_t key, bool& found) { return m_table.find_or_add(key, found); }
    /// Brings `key`'s first probe into the host's cache (speed only).
    void prefetch(uint64_t key) const { m_table.prefetch(key); }
    void clear() { m_table.clear(); }
    size_t size() const { return m_table.size(); }

private:
    struct Hash {
        size_t operator()(uint64_t key) const { return size_t((key * 0x9E3779B97F4A7C15ull) >> 20); }
    };
    ProbeTable<uint64_t, uint64_t, Hash, HugePageAllocator> m_table;
};

}  // namespace rtsim
