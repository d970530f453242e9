#pragma once
// Functional warming for sampled runs (docs/fidelity.md, "Sampling"): before each cluster, the
// skipped rays just before it are traversed with the structure's stepper, without time, and every
// line the model would read for them (the ray record, the nodes, leaves and triangles each step
// fetches) is made present in the L1 of the unit the interleaved dispatch would give the ray and
// in the shared L2. This is SMARTS's functional warming (Wunderlich et al., ISCA 2003) limited to
// the rays before each cluster, as in Haskins & Skadron's MRRL (2003): the L2 holds the lines of
// a few thousand rays, so older rays leave nothing behind. Stack spills and hit writes are not
// replayed (write-through, no-write-allocate: they do not change the caches), nor treelet ray
// buffers (their queues hold rays, not lines; the detailed warm-up fills them).
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "rtl_model/common/memory_map.h"
#include "rtl_model/traversal/step_demand.h"
#include "traces/accel/accel.h"
#include "traces/format/trace_reader.h"

namespace rtsim {

/// Makes a read of [addr, addr + bytes) by unit `unit` present in the caches (Top::warm).
using WarmRead = std::function<void(uint32_t unit, uint64_t addr, uint32_t bytes)>;

class FunctionalWarmer {
public:
    FunctionalWarmer(const Accel& accel, const StepOptions& step, const StepCosts& costs, const MemoryMap& map,
                     TraceReader& reader,
                     uint32_t units, WarmRead warm);
    /// Replays rays [first, end) of the trace, in order, through the caches. `next_unit` is the
    /// unit the dispatch deals ray `end` to (interleaved, block_rays = 1: consecutive rays go to
    /// consecutive units), so each warmed ray warms the L1 of the unit that would have run it.
    void warm(uint64_t first, uint64_t end, uint32_t next_unit);

    uint64_t warmed_rays() const { return m_rays; }
    uint64_t warmed_reads() const { return m_reads; }
    double seconds() const { return m_seconds; }

private:
    const StepCosts m_costs;
    const MemoryMap& m_map;
    TraceReader& m_reader;
    uint32_t m_units;
    WarmRead m_warm;
    std::unique_ptr<Stepper> m_stepper;
    std::vector<RayRecord> m_records;
    uint64_t m_rays = 0, m_reads = 0;
    double m_seconds = 0;
};

}  // namespace rtsim
