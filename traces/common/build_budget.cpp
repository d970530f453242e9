// build_memory_limit_bytes and check_build_memory (build_budget.h).
#include "traces/common/build_budget.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "traces/common/error.h"

namespace rtsim {

namespace {

/// Bytes of address space the process maps now (/proc/self/statm: size in pages), 0 if unknown.
uint64_t mapped_bytes() {
    std::ifstream statm("/proc/self/statm");
    uint64_t pages = 0;
    if (!(statm >> pages)) return 0;
    const long page = sysconf(_SC_PAGESIZE);
    return pages * uint64_t(page > 0 ? page : 4096);
}

/// What a resource limit leaves beside what is mapped (80% of it: the allocator's own overhead
/// and the rest of the process), or UINT64_MAX when it is unlimited.
uint64_t left_under(int resource) {
    struct rlimit r {};
    if (getrlimit(resource, &r) != 0 || r.rlim_cur == RLIM_INFINITY) return UINT64_MAX;
    const uint64_t limit = uint64_t(r.rlim_cur), used = mapped_bytes();
    return limit > used ? (limit - used) / 5 * 4 : 0;
}

}  // namespace

uint64_t build_memory_limit_bytes() {
    if (const char* env = std::getenv("RTSIM_BUILD_MEMORY_LIMIT_MIB")) {
        char* end = nullptr;
        const unsigned long long mib = std::strtoull(env, &end, 10);
        if (end != env && *end == '\0' && mib > 0 && mib < (1ull << 40)) return mib << 20;
    }
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    const uint64_t memory = pages > 0 && page > 0 ? uint64_t(pages) * uint64_t(page) : (uint64_t(8) << 30);
    return std::min({memory / 2, left_under(RLIMIT_AS), left_under(RLIMIT_DATA)});
}

std::string format_bytes(double bytes) {
    char text[64];
    if (bytes >= double(1ull << 30)) std::snprintf(text, sizeof text, "%.1f GiB", bytes / double(1ull << 30));
    else std::snprintf(text, sizeof text, "%.1f MiB", bytes / double(1ull << 20));
    return text;
}

void check_build_memory(double bytes, const std::string& what, const std::string& detail, const std::string& advice) {
    const uint64_t limit = build_memory_limit_bytes();
    if (bytes <= double(limit)) return;
    throw Error(what + " needs about " + format_bytes(bytes) + " (" + detail + "), more than the " +
                format_bytes(double(limit)) +
                " a build may take here (half the physical memory, within ulimit -v/-d; "
                "RTSIM_BUILD_MEMORY_LIMIT_MIB overrides); " + advice);
}

}  // namespace rtsim
