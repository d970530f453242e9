#include "sim/analytic/reuse.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rtsim {

int DistanceBins::bin(uint64_t d) {
    if (d <= 1) return 0;
    const int octave = 63 - __builtin_clzll(d);
    const uint64_t base = 1ull << octave;
    const int sub = int(((d - base) * kSubBins) >> octave);
    return std::min(octave * kSubBins + sub, kBins - 1);
}

double DistanceBins::low(int b) {
    const int octave = b / kSubBins, sub = b % kSubBins;
    return std::ldexp(1.0 + double(sub) / kSubBins, octave);
}

double DistanceBins::high(int b) { return low(b + 1); }

ReuseCurve::ReuseCurve(const std::vector<double>& events, const std::vector<double>& censored)
    : m_surv(DistanceBins::kBins, 1.0), m_sd(DistanceBins::kBins, 0.0) {
    // Kaplan-Meier: an observation censored in bin b is at risk through bin b.
    double at_risk = 0;
    for (int b = 0; b < DistanceBins::kBins; ++b) at_risk += events[b] + censored[b];
    double s = 1.0, sd = 0.0;
    for (int b = 0; b < DistanceBins::kBins; ++b) {
        const double start = s;
        if (at_risk > 0) s *= 1.0 - events[b] / at_risk;
        at_risk -= events[b] + censored[b];
        m_surv[b] = s;
        // sum_{m} P(RD > m) over the bin's integers, trapezoid between its edges.
        sd += (DistanceBins::high(b) - DistanceBins::low(b)) * 0.5 * (start + s);
        m_sd[b] = sd;
    }
}

double ReuseCurve::survival(double d) const {
    if (d < 1) return 1.0;
    const int b = DistanceBins::bin(uint64_t(d));
    const double lo = DistanceBins::low(b), hi = DistanceBins::high(b);
    const double start = b ? m_surv[b - 1] : 1.0;
    const double f = std::clamp((d - lo) / (hi - lo), 0.0, 1.0);
    return start + f * (m_surv[b] - start);
}

double ReuseCurve::stack_distance(double d) const {
    if (d <= 1) return 0.0;
    const int b = DistanceBins::bin(uint64_t(d));
    const double lo = DistanceBins::low(b);
    const double before = b ? m_sd[b - 1] : 0.0;
    const double start = b ? m_surv[b - 1] : 1.0;
    return before + std::max(0.0, d - lo) * 0.5 * (start + survival(d));
}

double ReuseCurve::distance_for(double lines) const {
    if (lines <= 0) return 1.0;
    const auto it = std::lower_bound(m_sd.begin(), m_sd.end(), lines);
    if (it == m_sd.end()) return std::numeric_limits<double>::infinity();
    const int b = int(it - m_sd.begin());
    double lo = DistanceBins::low(b), hi = DistanceBins::high(b);
    for (int i = 0; i < 40; ++i) {  // stack_distance is monotone in d
        const double mid = 0.5 * (lo + hi);
        (stack_distance(mid) >= lines ? hi : lo) = mid;
    }
    return hi;
}

double lru_hit_probability(double sd, double lines, uint32_t ways) {
    const double sets = lines / ways;
    if (sets < 2) return sd < lines ? 1.0 : 0.0;
    // P(Poisson(sd / sets) < ways): Binomial(sd, 1/sets) with many sets.
    const double lambda = sd / sets;
    double term = std::exp(-lambda), sum = 0;
    for (uint32_t k = 0; k < ways; ++k) {
        sum += term;
        term *= lambda / double(k + 1);
    }
    return std::min(1.0, sum);
}

double bin_miss_probability(const ReuseCurve& curve, int b, bool censored, double lines, uint32_t ways,
                            bool censored_is_cold) {
    if (censored && censored_is_cold) return 1.0;
    constexpr int kPoints = 4;
    const double lo = DistanceBins::low(b), hi = DistanceBins::high(b);
    double miss = 0;
    for (int k = 0; k < kPoints; ++k) {
        const double d = lo * std::pow(hi / lo, (k + 0.5) / kPoints);
        if (!censored) {
            miss += 1.0 - lru_hit_probability(curve.stack_distance(d), lines, ways);
            continue;
        }
        // Known only to exceed d: hit with probability E[hit | RD > d], integrated over the
        // curve's mass beyond d (bin by bin, each at its middle).
        const double s = curve.survival(d);
        if (s <= 1e-12) {
            miss += 1.0;
            continue;
        }
        double hit = 0, prev = s;
        for (int c = DistanceBins::bin(uint64_t(d)); c < DistanceBins::kBins && prev > 1e-12; ++c) {
            const double edge = std::max(d, DistanceBins::high(c));
            const double next = curve.survival(edge);
            const double mid = std::sqrt(std::max(d, DistanceBins::low(c)) * edge);
            hit += (prev - next) * lru_hit_probability(curve.stack_distance(mid), lines, ways);
            prev = next;
        }
        miss += 1.0 - hit / s;
    }
    return miss / kPoints;
}

}  // namespace rtsim
