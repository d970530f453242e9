#pragma once
// SIMT shader cores as an approximately-timed resource (docs/shading.md, "Shader cores"): a warp
// of lanes runs each distinct program of its lanes one after another (SIMT divergence: Aila &
// Laine 2009's SIMD efficiency), issuing warp instructions at issue_per_cycle; its texture
// samples read the lines their lanes' texels fall in (coalesced per sample instruction) through
// the core's texture cache. A core keeps warps_resident warps in flight, so texture latency is
// hidden by other warps' issue until that many wait. No clock: each core is a calendar of its
// issue slot and a heap of its resident warps' ends.
#include <cstdint>
#include <queue>
#include <vector>

#include "rtl_model/common/interfaces.h"
#include "rtl_model/shading/shading_config.h"

namespace rtsim {

/// One lane's program: its instruction count and the texel addresses it samples.
struct LaneProgram {
    uint32_t program = 0;       ///< program id (a hit shader, the miss shader, shadow result, raygen)
    uint32_t instructions = 0;  ///< per lane
    uint32_t samples = 0;       ///< texture samples (kTexelsPerSample texels each, in `texels`)
    const uint64_t* texels = nullptr;
};

/// What shading one warp did.
struct WarpResult {
    Cycle start = 0, issue_end = 0, end = 0;
    uint32_t programs = 0;        ///< distinct programs (1: no divergence)
    uint64_t issued = 0;          ///< warp instructions issued
    uint64_t lane_instructions = 0;  ///< instructions the lanes needed (useful work)
    uint64_t tex_lines = 0;       ///< texture-cache line reads
    uint32_t core = 0;
};

class ShaderCores {
public:
    /// `tex[c]`: core c's texture cache (null: no texture model).
    ShaderCores(const ShadingConfig& config, std::vector<MemIf*> tex);

    /// Runs a warp of `lanes` whose inputs are ready at `ready`; returns when and what it did.
    WarpResult run(const std::vector<LaneProgram>& lanes, Cycle ready);
    /// Every core idle from `cycle` on (a frame barrier: no warp issues earlier).
    void advance_to(Cycle cycle);
    /// Cycle-count of issue slots used so far, summed over cores.
    uint64_t issue_busy() const { return m_issue_busy; }

private:
    const ShadingConfig& m_config;
    std::vector<MemIf*> m_tex;
    std::vector<Cycle> m_issue_free;  ///< per core: when its issue slot is next free
    std::vector<std::priority_queue<Cycle, std::vector<Cycle>, std::greater<Cycle>>> m_resident;
    uint64_t m_issue_busy = 0;
    std::vector<uint64_t> m_lines;  ///< scratch: one sample instruction's distinct lines
};

}  // namespace rtsim
