#pragma once
// Configuration of the analytic level (docs/fidelity.md, "The analytic level"), owned by the
// harness: which cache model it uses and how its per-trace analysis samples the trace.
#include <algorithm>
#include <cstdint>

#include "rtl_model/common/choice.h"

namespace rtsim {

enum class AnalyticCaches : uint8_t { statistical = 0, functional = 1 };
inline constexpr Choices<AnalyticCaches, 2> kAnalyticCachesChoices{{"statistical", "functional"}};

struct AnalyticConfig {
    /// statistical: reuse distances of a sample of rays (StatStack) and the trace's work counts;
    /// functional: every ray stepped through functional caches (exact hit rates, ~50x slower)
    AnalyticCaches caches = AnalyticCaches::statistical;
    uint32_t whole_trace_rays = 32768;  ///< traces up to this many rays are analysed whole
    uint32_t clusters = 8;              ///< else this many clusters of consecutive rays, each
    uint32_t warmup_rays = 0;           ///< with this many warm-up rays (history only); 0: automatic
    uint32_t measured_rays = 1024;      ///< and this many measured rays

    /// The warm-up rays per cluster: warmup_rays, or with 0 max(3072, L2 lines / 4) (a ray of an
    /// incoherent frame touches about 4 new lines; a 4 MiB L2's reuse needs ~16 k rays of history).
    uint32_t resolved_warmup_rays(uint64_t l2_lines) const {
        if (warmup_rays) return warmup_rays;
        return uint32_t(std::max<uint64_t>(kMinWarmupRays, std::min<uint64_t>(l2_lines / 4, 1u << 24)));
    }
    static constexpr uint32_t kMinWarmupRays = 3072;

    template <class V>
    void visit(V& v) {
        v.choice("caches", caches, kAnalyticCachesChoices, "statistical: reuse distances of a sample of rays (StatStack) scaled by the trace's work counts; functional: every ray through functional caches (exact, slow)");
        v.field("whole_trace_rays", whole_trace_rays, "rays", "Traces up to this many rays are analysed whole (statistical caches)", 0, 1u << 30);
        v.field("clusters", clusters, "clusters", "Clusters of consecutive rays the analysis steps in larger traces", 1, 4096);
        v.field("warmup_rays", warmup_rays, "rays", "Warm-up rays per cluster: their accesses only build reuse history; 0: automatic, max(3072, L2 lines / 4), enough history to see the L2's reuse", 0, 1u << 24);
        v.field("measured_rays", measured_rays, "rays", "Measured rays per cluster", 1, 1u << 24);
    }
};

}  // namespace rtsim
