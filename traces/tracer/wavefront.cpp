#include "traces/tracer/wavefront.h"

#include <algorithm>
#include <atomic>
#include <thread>


namespace rtsim {

namespace {
constexpr uint64_t kBlock = 2048;  // rays per work item: big enough to amortise the atomic
}

WavefrontResult trace_wavefront(const Accel& accel, const std::vector<PendingRay>& rays, unsigned threads,
                                const std::function<void(uint64_t)>& progress, const StepOptions& step) {
    WavefrontResult result;
    result.hits.resize(rays.size());
    result.work.resize(rays.size());
    const uint64_t blocks = (rays.size() + kBlock - 1) / kBlock;
    std::atomic<uint64_t> next_block{0}, done{0}, rejected{0};

    auto worker = [&](bool report) {
        uint64_t local_rejected = 0;
        for (uint64_t b; (b = next_block.fetch_add(1)) < blocks;) {
            uint64_t end = std::min<uint64_t>(rays.size(), (b + 1) * kBlock);
            for (uint64_t i = b * kBlock; i < end; ++i) {
                const PendingRay& r = rays[i];
                if (!ray_is_valid(r.ray)) ++local_rejected;
                TraversalMode mode = r.any_hit ? TraversalMode::any_hit : TraversalMode::closest_hit;
                result.hits[i] = accel.trace(r.ray, mode, &result.work[i], step);
            }
            uint64_t now = done.fetch_add(end - b * kBlock) + (end - b * kBlock);
            if (report && progress) progress(now);
        }
        rejected += local_rejected;
    };

    unsigned n = threads ? threads : std::max(1u, std::thread::hardware_concurrency());
    n = unsigned(std::min<uint64_t>(n, std::max<uint64_t>(1, blocks)));
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < n; ++t) pool.emplace_back(worker, false);
    try {
        worker(true);
    } catch (...) {
        // The progress callback threw (e.g. Ctrl-C from Python): stop the workers, then rethrow.
        next_block = blocks;
        for (std::thread& t : pool) t.join();
        throw;
    }
    for (std::thread& t : pool) t.join();
    if (progress) progress(rays.size());
    result.rejected = rejected;
    return result;
}

}  // namespace rtsim
