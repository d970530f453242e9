// estimate_sim_memory: the measured per-item costs of memory_estimate.h, summed in double (the
// products of in-range fields overflow nothing there) and compared with the limit.
#include "sim/harness/memory_estimate.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>

#include "traces/common/error.h"

namespace rtsim {

namespace {

constexpr double kBase = 16.0 * (1 << 20);
constexpr double kPerUnit = 280.0 * 1024;
constexpr double kPerContext = 1.1 * 1024;
constexpr double kPerAnalyticContext = 1.35 * 1024;  // a stepper in a std::vector slot
constexpr double kPerCacheLine = 24.0;
constexpr double kGiB = double(1ull << 30);

double cache_lines(const CacheConfig& c) { return double(c.size_kib) * 1024.0 / double(c.line_bytes); }

}  // namespace

uint64_t memory_limit_bytes() {
    if (const char* env = std::getenv("RTSIM_SIM_MEMORY_LIMIT_MIB")) {
        char* end = nullptr;
        const unsigned long long mib = std::strtoull(env, &end, 10);
        if (end != env && *end == '\0' && mib > 0 && mib < (1ull << 40)) return mib << 20;
    }
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    const uint64_t memory = pages > 0 && page > 0 ? uint64_t(pages) * uint64_t(page) : (uint64_t(8) << 30);
    return memory / 2;
}

MemoryEstimate estimate_sim_memory(const SimConfig& c, uint64_t image_bytes) {
    const double image = 2.0 * double(image_bytes);
    const double units = c.traversal.units;
    const double contexts = units * c.traversal.contexts();
    double model = 0.0, context_bytes = 0.0, l1 = 0.0, l2 = 0.0;
    if (c.fidelity != Fidelity::functional) {
        l1 = units * cache_lines(c.l1) * kPerCacheLine;
        l2 = cache_lines(c.l2) * kPerCacheLine;
    }
    if (c.fidelity == Fidelity::approx || c.fidelity == Fidelity::detailed) {
        model = units * kPerUnit;
        context_bytes = contexts * kPerContext;
    }
    // The analytic level's functional caches step every ray in a context of its own (a stepper
    // and its stack, as a SystemC context holds), without the units' modules.
    if (c.fidelity == Fidelity::analytic && c.analytic.caches == AnalyticCaches::functional)
        context_bytes = contexts * kPerAnalyticContext;
    const double total = kBase + image + model + context_bytes + l1 + l2;
    const double per_context = (context_bytes > 0 ? context_bytes / contexts : kPerContext) / 1024;
    char detail[256];
    std::snprintf(detail, sizeof detail,
                  "%.0f ray contexts x %.3g KiB = %.2f GiB, %.0f units = %.2f GiB, L1s %.2f GiB, L2 %.2f GiB, "
                  "structure image %.2f GiB",
                  contexts, per_context, context_bytes / kGiB, units, model / kGiB, l1 / kGiB, l2 / kGiB,
                  image / kGiB);
    return MemoryEstimate{uint64_t(total), memory_limit_bytes(), detail};
}

void check_sim_memory(const SimConfig& config, uint64_t image_bytes, const std::string& source) {
    const MemoryEstimate e = estimate_sim_memory(config, image_bytes);
    if (e.bytes <= e.limit) return;
    char text[160];
    std::snprintf(text, sizeof text, ": the model for this config needs about %.1f GiB of host memory (limit %.1f GiB, ",
                  double(e.bytes) / kGiB, double(e.limit) / kGiB);
    throw Error(source + text +
                "half the physical memory or RTSIM_SIM_MEMORY_LIMIT_MIB): " + e.detail +
                "; reduce traversal.units, traversal.ray_contexts or the cache sizes");
}

}  // namespace rtsim
