#pragma once
// Timing for rtsim-bench: wall time (steady clock) and the calling thread's CPU time
// (CLOCK_THREAD_CPUTIME_ID, which a shared machine's other load does not inflate), medians.
#include <time.h>

#include <algorithm>
#include <chrono>
#include <vector>

namespace rtsim::bench {

/// Seconds of wall time and of this thread's CPU time for one run.
struct Sample {
    double wall = 0.0;
    double cpu = 0.0;
};

inline double thread_cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

/// Times fn() once.
template <typename Fn>
Sample time_once(Fn&& fn) {
    const auto w0 = std::chrono::steady_clock::now();
    const double c0 = thread_cpu_seconds();
    fn();
    const double c1 = thread_cpu_seconds();
    const auto w1 = std::chrono::steady_clock::now();
    return {std::chrono::duration<double>(w1 - w0).count(), c1 - c0};
}

inline double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// Median wall and median CPU time over samples (each median taken separately).
inline Sample median(const std::vector<Sample>& samples) {
    std::vector<double> wall, cpu;
    for (const Sample& s : samples) {
        wall.push_back(s.wall);
        cpu.push_back(s.cpu);
    }
    return {median(wall), median(cpu)};
}

}  // namespace rtsim::bench
