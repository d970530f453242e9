#pragma once
// Configuration of the analytic level (docs/fidelity.md, "The analytic level"), owned by the
// harness: which cache model it uses and how its per-trace analysis samples the trace.
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
    uint32_t warmup_rays = 3072;        ///< with this many warm-up rays (history only)
    uint32_t measured_rays = 1024;      ///< and this many measured rays

    template <class V>
    void visit(V& v) {
        v.choice("caches", caches, kAnalyticCachesChoices, "statistical: reuse distances of a sample of rays (StatStack) scaled by the trace's work counts; functional: every ray through functional caches (exact, slow)");
        v.field("whole_trace_rays", whole_trace_rays, "rays", "Traces up to this many rays are analysed whole (statistical caches)", 0, 1u << 30);
        v.field("clusters", clusters, "clusters", "Clusters of consecutive rays the analysis steps in larger traces", 1, 4096);
        v.field("warmup_rays", warmup_rays, "rays", "Warm-up rays per cluster: their accesses only build reuse history", 0, 1u << 24);
        v.field("measured_rays", measured_rays, "rays", "Measured rays per cluster", 1, 1u << 24);
    }
};

}  // namespace rtsim
