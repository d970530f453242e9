#pragma once
// Dispatch: hands rays to the traversal units, refilling its buffer one chunk at a time from a
// RayStream (the harness streams the trace file; memory stays bounded, rule 8).
//
// interleaved (default): each chunk is dealt to per-unit queues in turn, block_rays consecutive
// rays at a time; a unit whose queue is empty steals from the back of the longest queue. The
// assignment is the hardware's policy and does not depend on how far units run ahead of each
// other (quantum_cycles), so the approx and detailed levels give rays to the same units.
// on_demand: the next ray in trace order goes to whichever unit asks first. With temporal
// decoupling a unit running ahead then takes runs of neighbouring rays, which flatters its L1.
#include <cstdint>
#include <deque>
#include <vector>

#include <nlohmann/json.hpp>
#include <systemc>

#include "rtl_model/common/interfaces.h"
#include "rtl_model/dispatch/dispatch_config.h"

namespace rtsim {

/// Where rays come from (implemented by the harness over the trace file).
class RayStream {
public:
    virtual ~RayStream() = default;
    /// Appends up to `max` rays in trace order to `out`; returns how many (0 at the end).
    virtual size_t read_chunk(size_t max, std::vector<RayJob>* out) = 0;
    virtual uint64_t total_rays() const = 0;
};

class Dispatch : public sc_core::sc_module, public RaySourceIf {
public:
    Dispatch(sc_core::sc_module_name name, const DispatchConfig& config, uint32_t units, RayStream& stream);

    bool next_ray(uint32_t unit, RayJob* job) override;
    uint64_t total_rays() const override { return m_stream.total_rays(); }
    uint64_t dispatched() const { return m_dispatched; }
    nlohmann::json stats_json() const;

private:
    bool next_on_demand(RayJob* job);
    bool next_interleaved(uint32_t unit, RayJob* job);
    bool deal_chunk();

    DispatchConfig m_config;
    RayStream& m_stream;
    std::vector<RayJob> m_buffer;  ///< on_demand: the current chunk
    size_t m_next = 0;
    std::vector<std::deque<RayJob>> m_queues;  ///< interleaved: per-unit queues
    uint32_t m_deal_unit = 0;                   ///< unit the next block goes to
    uint32_t m_any_unit = 0;                    ///< rotor for kAnyUnit requests
    bool m_stream_done = false;
    uint64_t m_dispatched = 0, m_chunks = 0, m_steals = 0;
};

}  // namespace rtsim
