#pragma once
// Configuration of statistical sampling (docs/fidelity.md), owned by the harness.
#include <cstdint>

namespace rtsim {

/// Statistical sampling (docs/fidelity.md): simulate a stratified sample of clusters of rays, each
/// warm-up then measured rays, and estimate the full run's cycles with a 95% confidence interval
/// (SMARTS, Wunderlich et al. 2003). Off unless fraction or count is set; needs a timed level.
struct SamplingConfig {
    double fraction = 0.0;      ///< fraction of the trace's rays simulated (warm-up included); 0: off
    uint32_t count = 0;         ///< rays simulated, instead of a fraction; 0: off
    uint32_t clusters = 30;     ///< strata, one cluster of rays each (fewer if the sample is small)
    uint32_t warmup_rays = 0;   ///< warm-up rays per cluster; 0: automatic (docs/fidelity.md)
    /// skipped rays before each cluster replayed through the caches without time (functional
    /// warming); 0: none (then the automatic warm-up also covers the L2: L2 lines / 8 rays).
    /// 4096 rays of Sponza diffuse refill a 1 MiB L2 (docs/fidelity.md); about L2 lines / 4.
    uint32_t warming_rays = 4096;
    uint32_t seed = 1;          ///< picks each cluster's offset within its stratum

    bool enabled() const { return fraction > 0 || count > 0; }

    template <class V>
    void visit(V& v) {
        v.field("fraction", fraction, "fraction", "Fraction of the trace's rays to simulate, warm-up included (0: no sampling)", 0.0, 1.0);
        v.field("count", count, "rays", "Rays to simulate instead of a fraction (0: no sampling)", 0, 2147483647.0);
        v.field("clusters", clusters, "clusters", "Strata of the trace, one sampled cluster each (fewer when the sample cannot hold them with their warm-up)", 2, 100000);
        v.field("warmup_rays", warmup_rays, "rays", "Warm-up rays simulated before each cluster's measured rays (0: automatic, docs/fidelity.md)", 0, 1u << 24);
        v.field("warming_rays", warming_rays, "rays", "Skipped rays before each cluster replayed through the L1s and L2 without time (functional warming, docs/fidelity.md; 0: none); about L2 lines / 4", 0, 2147483647.0);
        v.field("seed", seed, "seed", "Seed of each cluster's random offset within its stratum", 0, 2147483647.0);
    }
};

}  // namespace rtsim
