#include "sim/sampling/warming.h"

#include <algorithm>
#include <chrono>

namespace rtsim {

FunctionalWarmer::FunctionalWarmer(const Accel& accel, const StepOptions& step, const StepCosts& costs,
                                   const MemoryMap& map, TraceReader& reader, uint32_t units, WarmRead warm)
    : m_costs(costs),
      m_map(map), m_reader(reader), m_units(std::max<uint32_t>(units, 1)), m_warm(std::move(warm)),
      m_stepper(accel.make_stepper(step)) {}

void FunctionalWarmer::warm(uint64_t first, uint64_t end, uint32_t next_unit) {
    const auto t0 = std::chrono::steady_clock::now();
    constexpr uint64_t kBatch = 4096;  // rays read from the trace at a time
    for (uint64_t at = first; at < end; at += kBatch) {
        const uint64_t n = std::min(kBatch, end - at);
        m_records.resize(size_t(n));
        m_reader.read(SectionKind::rays, at, n, m_records.data());
        for (uint64_t i = 0; i < n; ++i) {
            const uint64_t id = at + i;
            const RayRecord& rec = m_records[size_t(i)];
            // Interleaved dispatch deals consecutive rays to the units in turn (block_rays = 1).
            const uint32_t unit = uint32_t((next_unit + m_units - (end - id) % m_units) % m_units);
            m_warm(unit, m_map.ray(id), uint32_t(sizeof(RayRecord)));
            m_stepper->begin(ray_from_record(rec), (rec.flags & kRayFlagAnyHit) ? TraversalMode::any_hit : TraversalMode::closest_hit);
            StackSplit stack;
            StepDemand d;
            while (!m_stepper->done()) {
                take_step(*m_stepper, stack, m_costs, d);
                for (int f = 0; f < d.read_count; ++f) m_warm(unit, d.reads[f].addr, d.reads[f].bytes);
                m_reads += uint64_t(d.read_count);
            }
        }
        m_rays += n;
    }
    m_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace rtsim
