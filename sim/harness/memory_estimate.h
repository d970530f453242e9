#pragma once
// Host memory a simulation will need, estimated from the config before the SystemC model is
// elaborated, so an absurd but in-range config (4096 units x 4096 ray contexts) is refused with
// the figure instead of dying in std::bad_alloc halfway through elaboration.
//
// The estimate is linear in what the model allocates up front; its constants were measured
// with /usr/bin/time (peak RSS) on rtsim-sim over unit, context and cache sizes (docs/validation.md):
//   base process (SystemC kernel, stats, buffers)        16 MiB
//   acceleration-structure image (read, then loaded)    2 x its bytes
//   per traversal unit (module, thread stack, pipelines)  280 KiB + its L1 lines x 24 B
//   per ray context (traversal stepper and stack)        1.1 KiB (approx, detailed)
//   per analytic context (analytic.caches = functional)  1.35 KiB (1.33 measured: 64 units x
//                                                        1,024 to 4,096 contexts, Cornell)
//   L2                                                   lines x 24 B
// Queues that grow with the run (treelet ray queues, the DRAM timeline) are not included.
#include <cstdint>
#include <string>

#include "sim/config/config.h"

namespace rtsim {

struct MemoryEstimate {
    uint64_t bytes = 0;  ///< estimated peak host memory of the run
    uint64_t limit = 0;  ///< largest estimate accepted (see memory_limit_bytes)
    std::string detail;  ///< what dominates, e.g. "16777216 ray contexts x 1.1 KiB"
};

/// The estimate for `config` with an acceleration-structure image of `image_bytes`.
MemoryEstimate estimate_sim_memory(const SimConfig& config, uint64_t image_bytes);

/// Half of this machine's physical memory (a sweep runs one simulation per core beside the
/// tracer), or RTSIM_SIM_MEMORY_LIMIT_MIB when set (a positive integer of MiB).
uint64_t memory_limit_bytes();

/// Throws rtsim::Error "<source>: the model for this config needs about X GiB ... (limit Y GiB)"
/// when the estimate exceeds the limit.
void check_sim_memory(const SimConfig& config, uint64_t image_bytes, const std::string& source);

}  // namespace rtsim
